#include "common/frontend/tracker_options.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "common/config/config.h"

namespace vimot::frontend {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("feature tracker options: " + what);
}

// A misspelt key would otherwise leave its default silently in force.
void only_keys(const Config& cfg, const std::string& key, const std::vector<std::string>& allowed) {
  if (!cfg.has(key)) return;
  for (const std::string& k : cfg.sub(key).keys()) {
    if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
      std::string list;
      for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
      cfg.fail(key + "." + k, "is unknown (expected one of: " + list + ")");
    }
  }
}

template <typename T>
void read(const Config& cfg, const std::string& key, T* value) {
  *value = cfg.get_or<T>(key, *value);
}

}  // namespace

void StaticTrackOptions::validate() const {
  require(num_features > 0, "static.num_features must be > 0");
  require(grid_cols > 0 && grid_rows > 0, "static.grid_cols and grid_rows must be > 0");
  require(fast_threshold > 0 && fast_threshold < 255, "static.fast_threshold must be in 1..254");
  require(min_distance_px >= 0.0, "static.min_distance_px must be >= 0");
  require(border_px >= 0, "static.border_px must be >= 0");
  require(klt_window_px >= 3 && klt_window_px % 2 == 1, "static.klt_window_px must be odd and >= 3");
  require(klt_pyramid_levels >= 0 && klt_pyramid_levels <= 8, "static.klt_pyramid_levels must be in 0..8");
  require(klt_max_iterations > 0, "static.klt_max_iterations must be > 0");
  require(klt_epsilon > 0.0, "static.klt_epsilon must be > 0");
  require(max_track_frames >= 0, "static.max_track_frames must be >= 0");
  require(anchor_min_zncc >= -1.0 && anchor_min_zncc <= 1.0, "static.anchor_min_zncc must be in [-1, 1]");
  require(anchor_max_correction_px > 0.0, "static.anchor_max_correction_px must be > 0");
  require(anchor_max_scale > 1.0, "static.anchor_max_scale must be > 1");
}

void TargetTrackOptions::validate() const {
  require(num_features > 0, "target.num_features must be > 0");
  require(orb_fast_threshold > 0 && orb_fast_threshold < 255, "target.orb_fast_threshold must be in 1..254");
  require(orb_levels >= 1, "target.orb_levels must be >= 1");
  require(orb_scale_factor > 1.0, "target.orb_scale_factor must be > 1");
  require(max_hamming > 0 && max_hamming <= 256, "target.max_hamming must be in 1..256");
  require(match_ratio > 0.0 && match_ratio <= 1.0, "target.match_ratio must be in (0, 1]");
  require(max_motion_px > 0.0, "target.max_motion_px must be > 0");
  require(loop_closure_max_hamming >= 0 && loop_closure_max_hamming <= 256,
          "target.loop_closure_max_hamming must be in 0..256");
  require(max_stored_points >= 0, "target.max_stored_points must be >= 0");
  require(frame_to_frame == "orb" || frame_to_frame == "klt",
          "target.frame_to_frame must be orb or klt, got '" + frame_to_frame + "'");
  require(min_distance_px >= 0.0, "target.min_distance_px must be >= 0");
  require(grid >= 1, "target.grid must be >= 1");
  require(stereo == "descriptor" || stereo == "klt", "target.stereo must be descriptor or klt, got '" + stereo + "'");
  require(klt() || (!stereo_klt() && !anchor_align),
          "target.stereo klt and target.anchor_align need target.frame_to_frame klt");
}

void RansacOptions::validate() const {
  require(threshold_px > 0.0, "ransac.threshold_px must be > 0");
  require(confidence > 0.0 && confidence < 1.0, "ransac.confidence must be in (0, 1)");
  require(max_iterations > 0, "ransac.max_iterations must be > 0");
  require(min_points >= 8, "ransac.min_points must be >= 8 (the 8-point algorithm)");
}

void FeatureTrackerOptions::validate() const {
  static_tracks.validate();
  target.validate();
  ransac.validate();
}

FeatureTrackerOptions FeatureTrackerOptions::from_config(const Config& cfg, const std::string& section) {
  FeatureTrackerOptions o;
  const std::string s = section.empty() ? "" : section + ".";
  if (!section.empty()) only_keys(cfg, section, {"static", "target", "ransac"});
  only_keys(cfg, s + "static",
            {"equalize", "num_features", "grid_cols", "grid_rows", "fast_threshold", "min_distance_px", "border_px",
             "klt_window_px", "klt_pyramid_levels", "klt_max_iterations", "klt_epsilon",
             "max_track_frames", "anchor_align", "anchor_min_zncc", "anchor_max_correction_px", "anchor_max_scale"});
  only_keys(cfg, s + "target",
            {"num_features", "orb_fast_threshold", "orb_levels", "orb_scale_factor", "max_hamming", "match_ratio",
             "max_motion_px", "loop_closure_max_hamming", "max_stored_points", "frame_to_frame", "min_distance_px",
             "stereo", "anchor_align", "grid", "use_mask"});
  only_keys(cfg, s + "ransac", {"threshold_px", "confidence", "max_iterations", "min_points", "seed"});

  StaticTrackOptions& st = o.static_tracks;
  read(cfg, s + "static.equalize", &st.equalize);
  read(cfg, s + "static.num_features", &st.num_features);
  read(cfg, s + "static.grid_cols", &st.grid_cols);
  read(cfg, s + "static.grid_rows", &st.grid_rows);
  read(cfg, s + "static.fast_threshold", &st.fast_threshold);
  read(cfg, s + "static.min_distance_px", &st.min_distance_px);
  read(cfg, s + "static.border_px", &st.border_px);
  read(cfg, s + "static.klt_window_px", &st.klt_window_px);
  read(cfg, s + "static.klt_pyramid_levels", &st.klt_pyramid_levels);
  read(cfg, s + "static.klt_max_iterations", &st.klt_max_iterations);
  read(cfg, s + "static.klt_epsilon", &st.klt_epsilon);
  read(cfg, s + "static.max_track_frames", &st.max_track_frames);
  read(cfg, s + "static.anchor_align", &st.anchor_align);
  read(cfg, s + "static.anchor_min_zncc", &st.anchor_min_zncc);
  read(cfg, s + "static.anchor_max_correction_px", &st.anchor_max_correction_px);
  read(cfg, s + "static.anchor_max_scale", &st.anchor_max_scale);

  TargetTrackOptions& t = o.target;
  read(cfg, s + "target.num_features", &t.num_features);
  read(cfg, s + "target.orb_fast_threshold", &t.orb_fast_threshold);
  read(cfg, s + "target.orb_levels", &t.orb_levels);
  read(cfg, s + "target.orb_scale_factor", &t.orb_scale_factor);
  read(cfg, s + "target.max_hamming", &t.max_hamming);
  read(cfg, s + "target.match_ratio", &t.match_ratio);
  read(cfg, s + "target.max_motion_px", &t.max_motion_px);
  read(cfg, s + "target.loop_closure_max_hamming", &t.loop_closure_max_hamming);
  read(cfg, s + "target.max_stored_points", &t.max_stored_points);
  read(cfg, s + "target.frame_to_frame", &t.frame_to_frame);
  read(cfg, s + "target.min_distance_px", &t.min_distance_px);
  read(cfg, s + "target.stereo", &t.stereo);
  read(cfg, s + "target.anchor_align", &t.anchor_align);
  read(cfg, s + "target.grid", &t.grid);
  read(cfg, s + "target.use_mask", &t.use_mask);

  RansacOptions& r = o.ransac;
  read(cfg, s + "ransac.threshold_px", &r.threshold_px);
  read(cfg, s + "ransac.confidence", &r.confidence);
  read(cfg, s + "ransac.max_iterations", &r.max_iterations);
  read(cfg, s + "ransac.min_points", &r.min_points);
  int64_t seed = static_cast<int64_t>(r.seed);
  read(cfg, s + "ransac.seed", &seed);
  if (seed < 0) cfg.fail(s + "ransac.seed", "must be >= 0, got " + std::to_string(seed));
  r.seed = static_cast<uint64_t>(seed);

  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError("config '" + cfg.source() + "': " + s + e.what());
  }
  return o;
}

}  // namespace vimot::frontend

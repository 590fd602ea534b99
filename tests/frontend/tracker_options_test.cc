// FeatureTrackerOptions::from_config: the shipped config reads, a
// misspelt key or a bad value is refused naming the file and the key.
#include "common/frontend/tracker_options.h"

#include <catch2/catch.hpp>
#include <string>

#include "common/config/config.h"

using namespace vimot;
using frontend::FeatureTrackerOptions;

namespace {
std::string error_of(const std::string& yaml) {
  try {
    FeatureTrackerOptions::from_config(Config::from_string(yaml, "tracker.yaml"), "tracker");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}
}  // namespace

TEST_CASE("config/feature_tracker.yaml gives the built-in defaults") {
  const Config cfg = Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/feature_tracker.yaml");
  const FeatureTrackerOptions o = FeatureTrackerOptions::from_config(cfg, "tracker");
  const FeatureTrackerOptions d;
  CHECK(o.static_tracks.num_features == d.static_tracks.num_features);
  CHECK(o.static_tracks.klt_window_px == d.static_tracks.klt_window_px);
  CHECK(o.static_tracks.klt_epsilon == d.static_tracks.klt_epsilon);
  CHECK(o.static_tracks.equalize == d.static_tracks.equalize);
  CHECK(o.target.max_hamming == d.target.max_hamming);
  CHECK(o.target.loop_closure_max_hamming == d.target.loop_closure_max_hamming);
  CHECK(o.ransac.threshold_px == d.ransac.threshold_px);
  CHECK(o.ransac.max_iterations == d.ransac.max_iterations);
}

TEST_CASE("tracker options: values are read, unknown keys and bad values refused") {
  const FeatureTrackerOptions o = FeatureTrackerOptions::from_config(
      Config::from_string(
          "tracker:\n  static: {num_features: 120, klt_window_px: 11, max_track_frames: 20, anchor_align: true,\n"
          "           anchor_min_zncc: 0.7, anchor_max_correction_px: 1.5, anchor_max_scale: 1.5}\n"
          "  target: {frame_to_frame: klt, min_distance_px: 4, stereo: klt, anchor_align: true}\n"
          "  ransac: {threshold_px: 0.5}\n"),
      "tracker");
  CHECK(o.target.klt());
  CHECK(o.target.min_distance_px == 4.0);
  CHECK_FALSE(FeatureTrackerOptions().target.klt());
  CHECK(o.target.stereo_klt());
  CHECK(o.target.anchor_align);
  CHECK_FALSE(FeatureTrackerOptions().target.stereo_klt());
  CHECK_FALSE(FeatureTrackerOptions().target.anchor_align);
  CHECK(o.static_tracks.num_features == 120);
  CHECK(o.static_tracks.max_track_frames == 20);
  CHECK(o.static_tracks.anchor_align);
  CHECK(o.static_tracks.anchor_min_zncc == 0.7);
  CHECK(o.static_tracks.anchor_max_correction_px == 1.5);
  CHECK(o.static_tracks.anchor_max_scale == 1.5);
  CHECK(o.static_tracks.box_margin_px() == 5);
  CHECK(o.static_tracks.klt_window_px == 11);
  CHECK(o.ransac.threshold_px == 0.5);
  CHECK_THAT(error_of("tracker:\n  static: {num_feature: 120}\n"), Catch::Contains("tracker.static.num_feature") &&
                                                                       Catch::Contains("unknown") &&
                                                                       Catch::Contains("tracker.yaml"));
  CHECK_THAT(error_of("tracker:\n  stereo: {}\n"), Catch::Contains("tracker.stereo") && Catch::Contains("unknown"));
  CHECK_THAT(error_of("tracker:\n  static: {klt_window_px: 14}\n"), Catch::Contains("klt_window_px"));
  CHECK_THAT(error_of("tracker:\n  ransac: {min_points: 7}\n"), Catch::Contains("min_points"));
  CHECK_THAT(error_of("tracker:\n  static: {max_track_frames: -1}\n"), Catch::Contains("max_track_frames"));
  CHECK_THAT(error_of("tracker:\n  static: {anchor_min_zncc: 1.5}\n"), Catch::Contains("anchor_min_zncc"));
  CHECK_THAT(error_of("tracker:\n  static: {anchor_max_correction_px: 0}\n"),
             Catch::Contains("anchor_max_correction_px"));
  CHECK_THAT(error_of("tracker:\n  static: {anchor_max_scale: 1.0}\n"), Catch::Contains("anchor_max_scale"));
  CHECK_THAT(error_of("tracker:\n  target: {match_ratio: 1.5}\n"), Catch::Contains("match_ratio"));
  CHECK_THAT(error_of("tracker:\n  target: {frame_to_frame: lk}\n"), Catch::Contains("frame_to_frame"));
  CHECK_THAT(error_of("tracker:\n  target: {min_distance_px: -1}\n"), Catch::Contains("min_distance_px"));
  CHECK_THAT(error_of("tracker:\n  target: {frame_to_frame: klt, stereo: lk}\n"), Catch::Contains("target.stereo"));
  // Both follow KLT tracks: with ORB re-detection there are none.
  CHECK_THAT(error_of("tracker:\n  target: {stereo: klt}\n"), Catch::Contains("frame_to_frame klt"));
  CHECK_THAT(error_of("tracker:\n  target: {anchor_align: true}\n"), Catch::Contains("frame_to_frame klt"));
  CHECK(FeatureTrackerOptions::from_config(Config::from_string("tracker:\n  target: {use_mask: true}\n"), "tracker")
            .target.use_mask);
  CHECK_FALSE(FeatureTrackerOptions().target.use_mask);
  CHECK_THAT(error_of("tracker:\n  target: {use_mask: 8}\n"), Catch::Contains("target.use_mask"));
  CHECK_THAT(error_of("tracker:\n  target: {mask: true}\n"),
             Catch::Contains("target.mask") && Catch::Contains("unknown"));
  // Half the KLT window, rounded up: 15 -> 8, 11 -> 6.
  CHECK(FeatureTrackerOptions().static_tracks.target_mask_erode_px() == 8);
  CHECK(o.static_tracks.target_mask_erode_px() == 6);
}

// The monocular chain from pixels against the simulator's truth: the
// rendered mono scenario (config/sim_mono.yaml) through the feature tracker
// (config/feature_tracker_sim_mono.yaml, true target box) into the object
// tracker's node with the box as TARGET_BOX_TRUTH (config/object_tracker.yaml),
// as sheriff_configs/sim_mono_pixels.pmd runs them. The track's truth comes
// from the renderer's ray cast of its reference features
// (eval::object_truth_from_pixels), so nothing here uses the simulator's
// feature ids. The metric scale needs a 40 s window: its figures are
// vimot-scale-eval --pixels (docs/scale_estimator.md). With the target's
// points on its top face only (one lit face took every ORB slot) the
// structure was planar and the tracker committed to a wrong member of its
// family (79 deg); with points on the shaded faces too (target.grid,
// render.target_ambient; docs/feature_tracker.md, "Target points on every
// face") a track starts on the right structure. Its position then still
// missed the feature level's bound (0.072 m RMS here) while target tracks
// 1-3 px off across the box's edges went into the BA; ended by their anchor
// correlation (static.anchor_min_zncc 0.95), the position meets it
// (docs/scale_estimator.md, "From pixels").
#include <catch2/catch.hpp>

#include <cmath>
#include <deque>
#include <map>
#include <string>

#include "common/config/config.h"
#include "common/eval/object_truth.h"
#include "common/eval/pixel_frontend.h"
#include "common/frontend/tracker_options.h"
#include "common/math/quat.h"
#include "common/sim/sim_config.h"
#include "procs/object_tracker/object_tracker_node.h"

using namespace vimot;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

struct PixelRun {
  int frames_after_init{0};
  int valid{0};
  int tracks{0};
  double centre_ray_error_deg{-1.0};  // first track: its centre ray against the box centre's ray
  double position_rms_m{0.0};         // s_true pbar_OinC against the true p_OinC
  double position_max_m{0.0};
  double rotation_rms_deg{0.0};
  double rotation_max_deg{0.0};
};

// 6 s of config/sim_mono.yaml from pixels through the node, as the LCM chain.
PixelRun run_from_pixels() {
  cv::setNumThreads(1);
  sim::SimConfig config = sim::from_config(Config::load_file(source_path("config/sim_mono.yaml")));
  config.duration = 6.0;
  const sim::Simulator sim(config);
  eval::PixelFrontEnd front(
      sim, frontend::FeatureTrackerOptions::from_config(
               Config::load_file(source_path("config/feature_tracker_sim_mono.yaml")), "tracker"));
  ObjectPoseEstimate pose;
  ObjectTrackerNode node(
      object_tracker_options_from_config(Config::load_file(source_path("config/object_tracker.yaml"))),
      [&pose](const ObjectPoseEstimate& p) { pose = p; }, {});

  PixelRun run;
  std::deque<CameraFrame> recent;
  std::map<int64_t, Eigen::Vector2d> box_centre;  // px, by utime
  std::map<int64_t, eval::ObjectTruth> truths;
  double sum_pos2 = 0.0, sum_rot2 = 0.0;
  for (int64_t k = 0; k < sim.camera_frame_count(); ++k) {
    const int64_t utime = sim.camera_utime(k);
    const CameraFrame frame = front.frame(utime);
    recent.push_back(frame);
    const sim::RenderedView& view = front.last_views().at(0);
    REQUIRE(view.visible);
    const BoundingBox2d box{view.box.head<2>(), view.box.head<2>() + view.box.tail<2>()};
    node.on_box(utime, box);
    box_centre[utime] = 0.5 * (box.min_px + box.max_px);
    node.on_frame(frame);
    REQUIRE(pose.utime == utime);
    if (!node.tracker().init_facts()) continue;
    ++run.frames_after_init;
    if (!pose.valid) continue;
    ++run.valid;
    const InitFacts& facts = *node.tracker().init_facts();
    if (!truths.count(facts.track_id)) {
      const CameraFrame* reference = nullptr;
      for (const CameraFrame& f : recent) {
        if (f.utime == facts.reference_utime) reference = &f;
      }
      REQUIRE(reference != nullptr);
      truths[facts.track_id] = eval::object_truth_from_pixels(sim, front.renderer(), facts, *reference);
      if (truths.size() == 1) {
        // The tracker maps pixels to rays by an affine fit over the frame's
        // target features: exact up to the lens's curvature over the box.
        const Eigen::Vector2d xy = sim.camera_models().at(0).undistort(box_centre.at(facts.reference_utime));
        run.centre_ray_error_deg =
            std::acos(std::min(1.0, facts.centre_ray_C0.dot(xy.homogeneous().normalized()))) * 180.0 / M_PI;
      }
    }
    const eval::ObjectTruth& truth = truths.at(facts.track_id);
    const eval::TargetInCamera x = eval::true_target_in_camera(sim, utime);
    const double pos = (truth.s_true * pose.pbar_OinC - truth.p_OinC(x)).norm();
    sum_pos2 += pos * pos;
    run.position_max_m = std::max(run.position_max_m, pos);
    const double rot = rotation_angle_between(quat_to_rot(pose.q_OtoC), truth.R_OtoC(x));
    sum_rot2 += rot * rot;
    run.rotation_max_deg = std::max(run.rotation_max_deg, rot * 180.0 / M_PI);
  }
  run.tracks = static_cast<int>(truths.size());
  if (run.valid > 0) {
    run.position_rms_m = std::sqrt(sum_pos2 / run.valid);
    run.rotation_rms_deg = std::sqrt(sum_rot2 / run.valid) * 180.0 / M_PI;
  }
  return run;
}

const PixelRun& pixel_run() {
  static const PixelRun run = run_from_pixels();
  return run;
}

}  // namespace

TEST_CASE("object tracker from rendered pixels: a track starts on the right structure and holds",
          "[object_tracker][pixels]") {
  const PixelRun& run = pixel_run();
  INFO("valid " << run.valid << " of " << run.frames_after_init << " frames after the first initialisation, "
                << run.tracks << " tracks; centre ray vs the box centre's ray " << run.centre_ray_error_deg
                << " deg; pose against truth: position RMS " << run.position_rms_m << " m (max "
                << run.position_max_m << "), rotation RMS " << run.rotation_rms_deg << " deg (max "
                << run.rotation_max_deg << ")");
  // One track, never lost.
  REQUIRE(run.tracks == 1);
  CHECK(run.valid == run.frames_after_init);
  // No gross error: the feature-level tests' bound (object_tracker_test,
  // rotation RMS < 5 deg); a wrong structure is 20-170 deg off.
  CHECK(run.rotation_rms_deg < 5.0);
  // The feature-level tests' position bound (object_tracker_test: a
  // rotation error of about a degree moving O, d_ref from the camera).
  CHECK(run.position_rms_m < 0.05);
  CHECK(run.centre_ray_error_deg >= 0.0);
  CHECK(run.centre_ray_error_deg < 0.2);  // 1.6 px at f = 458 px
}

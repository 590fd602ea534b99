// The target filter from pixels (vimot-target-eval --pixels): the shipped
// rendered paper scenario (config/sim_paper.yaml) through the feature
// tracker (config/feature_tracker_sim.yaml, true box) into the joint robot +
// target filter as shipped (config/target_filter.yaml: SKF, local, started
// from its own target features), 8 s, against the simulator's truth.
#include <catch2/catch.hpp>

#include <string>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/estimator/vins_config.h"
#include "common/eval/target_eval.h"
#include "common/frontend/tracker_options.h"
#include "common/sim/sim_config.h"
#include "procs/eval/target_run.h"

using namespace vimot;

namespace {

const std::string kSource = VIMOT_SOURCE_DIR;

}  // namespace

TEST_CASE("target filter tracks the target from rendered pixels", "[eval][target][pixels]") {
  sim::SimConfig cfg = sim::from_config(Config::load_file(kSource + "/config/sim_paper.yaml"));
  cfg.duration = 8.0;
  const estimator::VioOptions vio = estimator::load_vio_options(kSource + "/config/vins.yaml");
  const target::TargetFilterOptions filter =
      eval::target_filter_options(Config::load_file(kSource + "/config/target_filter.yaml"));
  REQUIRE(filter.init_mode == target::TargetInitMode::kFeatures);  // no ground truth in the target's start
  const frontend::FeatureTrackerOptions pixels = frontend::FeatureTrackerOptions::from_config(
      Config::load_file(kSource + "/config/feature_tracker_sim.yaml"), "tracker");
  const uint64_t perturb = estimator::perturb_seed_for_run(cfg.seed);

  const eval::TargetRunResult r = eval::run_target_on_sim(cfg, vio, filter, perturb, {}, false, pixels);
  REQUIRE_FALSE(r.diverged);
  REQUIRE(r.target_initialized);
  const int64_t frames = r.imu.count;
  INFO("frames " << frames << ", with a target estimate " << r.target_in_imu.count << ", with target features "
                 << r.frames_with_target_obs << ", with a target update " << r.frames_with_target_update
                 << ", started after " << r.target_init_s << " s; target in IMU " << r.target_in_imu.rmse_position_m
                 << " m / " << r.target_in_imu.rmse_orientation_deg << " deg, NEES " << r.target_in_imu.nees_position
                 << " / " << r.target_in_imu.nees_orientation << ", max error " << r.target_max_error_m << " m");
  const double frame_s = 1.0 / cfg.camera.rate_hz;
  REQUIRE(frames >= static_cast<int64_t>(0.9 * cfg.duration / frame_s));
  // Tracked throughout: the start needs feature_init.frames consecutive
  // frames with enough stereo target points; after it every frame has target
  // features and (all but a few) updates the target.
  CHECK(r.target_init_s <= frame_s * (filter.feature_init.frames + 1));
  CHECK(r.target_in_imu.count == frames - filter.feature_init.frames + 1);
  CHECK(r.frames_with_target_obs == frames);
  CHECK(r.longest_gap_frames == 0);
  CHECK(r.frames_with_target_update >= r.target_in_imu.count - 5);
  // Against the truth (through the filter's own target frame): centimetres
  // and under two degrees for a 1 m cube a few metres away, never 10 cm off,
  // and the filter's covariance is not over-confident (mean NEES of a
  // consistent filter is 3; the evaluation accepts up to 6).
  CHECK(r.target_in_imu.rmse_position_m < 0.05);
  CHECK(r.target_in_imu.rmse_orientation_deg < 2.0);
  CHECK(r.target_max_error_m < 0.1);
  CHECK(r.target_in_imu.nees_position < 6.0);
  CHECK(r.target_in_imu.nees_orientation < 6.0);
  // The target's updates ran on the tracker's features: points in the state.
  CHECK(r.target_stats.points_initialized > 0);
  CHECK(r.target_stats.point_updates > 0);
}

// VioEstimator without the simulator: options from config, static
// initialisation, input robustness.

#include <catch2/catch.hpp>

#include <fstream>
#include <limits>
#include <sstream>
#include <random>

#include "common/config/config.h"
#include "common/estimator/vio_estimator.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::estimator;

namespace {

std::string calibration_path() { return std::string(VIMOT_SOURCE_DIR) + "/config/euroc_stereo.yaml"; }

Config with_estimator_section(const std::string& yaml) {
  // Calibration file contents plus an estimator section.
  std::ifstream in(calibration_path());
  std::stringstream ss;
  ss << in.rdbuf();
  return Config::from_string(ss.str() + "\n" + yaml, "test.yaml");
}

std::string error_of(const std::string& yaml) {
  try {
    VioOptions::from_config(with_estimator_section(yaml));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Options: defaults and keys from config", "[vio][config]") {
  const VioOptions d = VioOptions::from_config(Config::load_file(calibration_path()));
  CHECK(d.state.max_clones == 11);
  CHECK(d.state.max_slam == 50);
  CHECK(d.state.use_fej);
  CHECK(d.use_stereo);
  CHECK(d.cameras.size() == 2);
  CHECK(d.sigma_px == 1.0);
  CHECK(d.msckf.chi2_multiplier == 1.0);
  CHECK(d.propagator.noise.sigma_w == Approx(1.6968e-04));
  CHECK(d.propagator.noise.sigma_ab == Approx(3.0e-3));

  const VioOptions o = VioOptions::from_config(with_estimator_section(R"(
estimator:
  num_clones: 8
  max_slam: 20
  max_msckf_in_update: 15
  use_fej: false
  use_stereo: false
  slam_representation: anchored_inverse_depth
  sigma_px: 1.5
  msckf_chi2_multiplier: 2.0
  imu_noise:
    gyroscope_noise_density: 0.001
  init:
    mode: static
    max_accel_std: 0.3
  triangulation:
    max_depth: 40
)"));
  CHECK(o.state.max_clones == 8);
  CHECK(o.state.max_slam == 20);
  CHECK(o.msckf.max_features_per_update == 15);
  CHECK_FALSE(o.state.use_fej);
  CHECK_FALSE(o.use_stereo);
  CHECK(o.state.slam_representation == LandmarkRepresentation::kAnchoredInverseDepth);
  CHECK(o.sigma_px == 1.5);
  CHECK(o.msckf.chi2_multiplier == 2.0);
  CHECK(o.propagator.noise.sigma_w == 0.001);
  CHECK(o.init_mode == InitMode::kStatic);
  CHECK(o.static_init.max_accel_std == 0.3);
  CHECK(o.triangulation.max_depth == 40.0);
}

TEST_CASE("Options: errors name the key", "[vio][config]") {
  CHECK_THAT(error_of("estimator:\n  num_clones: 1\n"), Catch::Contains("estimator.num_clones"));
  CHECK_THAT(error_of("estimator:\n  num_clones: many\n"), Catch::Contains("estimator.num_clones"));
  CHECK_THAT(error_of("estimator:\n  sigma_px: -1\n"), Catch::Contains("estimator.sigma_px"));
  CHECK_THAT(error_of("estimator:\n  slam_representation: polar\n"), Catch::Contains("estimator.slam_representation"));
  CHECK_THAT(error_of("estimator:\n  init:\n    mode: magic\n"), Catch::Contains("estimator.init.mode"));
  CHECK_THAT(error_of("estimator:\n  triangulation:\n    max_depth: 0.01\n"),
             Catch::Contains("estimator.triangulation.max_depth"));
  const Config no_cams = Config::from_string("estimator:\n  num_clones: 5\n", "nocam.yaml");
  try {
    VioOptions::from_config(no_cams);
    FAIL("expected ConfigError");
  } catch (const ConfigError& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("cameras.cam0"));
  }
}

TEST_CASE("Static initialisation through the estimator", "[vio][static_init]") {
  VioOptions o = VioOptions::from_config(Config::load_file(calibration_path()));
  o.init_mode = InitMode::kStatic;
  VioEstimator est(o);
  const Eigen::Matrix3d R_GtoI = exp_so3(Eigen::Vector3d(-0.2, 0.1, 2.0));
  const Eigen::Vector3d bg(-0.003, 0.002, 0.001);
  std::mt19937 rng(4);
  std::normal_distribution<double> n01;
  const double sg = 1.6968e-04 / std::sqrt(0.005), sa = 2.0e-3 / std::sqrt(0.005);
  int64_t t = 1000000;
  for (int i = 0; i < 300 && !est.initialized(); ++i, t += 5000) {
    ImuData d;
    d.utime = t;
    d.w_IinI = bg + sg * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    d.a_IinI = R_GtoI * Eigen::Vector3d(0, 0, 9.81) + sa * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    est.feed_imu(d);
  }
  REQUIRE(est.initialized());
  const ImuValue x = est.imu_value();
  const Eigen::Vector3d up = quat_to_rot(x.q_GtoI) * Eigen::Vector3d::UnitZ();
  CHECK((up - R_GtoI * Eigen::Vector3d::UnitZ()).norm() < 2e-3);
  CHECK((x.bg - bg).norm() < 1e-3);
  // Covariance of the IMU block is the configured initial one.
  const Matrix15d P = est.imu_covariance();
  CHECK(P(3, 3) == Approx(o.init_sigmas.p * o.init_sigmas.p));
  CHECK(P(9, 9) == Approx(o.init_sigmas.bg * o.init_sigmas.bg));
  // Yaw variance sits about gravity: P_θ g_I = σ_yaw² g_I.
  const Eigen::Vector3d g_I = quat_to_rot(x.q_GtoI) * Eigen::Vector3d::UnitZ();
  CHECK((P.block<3, 3>(0, 0) * g_I - o.init_sigmas.theta_yaw * o.init_sigmas.theta_yaw * g_I).norm() < 1e-12);
}

TEST_CASE("Estimator input robustness", "[vio]") {
  VioEstimator est(VioOptions::from_config(Config::load_file(calibration_path())));
  CameraFrame frame;
  frame.utime = 2000000;
  FeatureObservation obs;
  obs.feature_id = 1;
  obs.normalized = Eigen::Vector2d(0.1, 0.2);
  frame.observations.push_back(obs);
  CHECK(est.feed_camera(frame) == FrameStatus::kNotInitialized);

  ImuValue x0;
  x0.q_GtoI = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, 0.3)));
  est.initialize(x0, 1000000);
  // No IMU data at all: cannot propagate.
  CHECK(est.feed_camera(frame) == FrameStatus::kNoImu);
  for (int i = 0; i <= 400; ++i) {
    ImuData d;
    d.utime = 1000000 + i * 5000;
    d.a_IinI = quat_to_rot(x0.q_GtoI) * Eigen::Vector3d(0, 0, 9.81);
    est.feed_imu(d);
  }
  ImuData nan;
  nan.utime = 4000000;
  nan.a_IinI.x() = std::numeric_limits<double>::quiet_NaN();
  CHECK(est.feed_imu(nan) == ImuFeedStatus::kRejectedNonFinite);
  ImuData dup;
  dup.utime = 3000000;
  CHECK(est.feed_imu(dup) == ImuFeedStatus::kRejectedDuplicate);

  // A target observation, an unknown camera and a non-finite point are skipped.
  FeatureObservation target = obs;
  target.feature_id = 2;
  target.is_target = true;
  FeatureObservation bad_cam = obs;
  bad_cam.feature_id = 3;
  bad_cam.camera_id = 5;
  FeatureObservation bad_uv = obs;
  bad_uv.feature_id = 4;
  bad_uv.normalized.x() = std::numeric_limits<double>::infinity();
  frame.observations = {obs, target, bad_cam, bad_uv};
  CHECK(est.feed_camera(frame) == FrameStatus::kProcessed);
  CHECK(est.target_observations_ignored() == 1);
  CHECK(est.invalid_observations() == 2);
  CHECK(est.state_utime() == 2000000);
  CHECK(est.clone_poses().size() == 1);
  // At rest the state stays put.
  CHECK(est.imu_value().p_IinG.norm() < 1e-9);
  // Same time again, and older: refused.
  CHECK(est.feed_camera(frame) == FrameStatus::kRejectedOutOfOrder);
  frame.utime = 1500000;
  CHECK(est.feed_camera(frame) == FrameStatus::kRejectedOutOfOrder);
  // Window bookkeeping: at most num_clones clones.
  for (int k = 1; k <= 15; ++k) {
    frame.utime = 2000000 + k * 100000;
    REQUIRE(est.feed_camera(frame) == FrameStatus::kProcessed);
  }
  CHECK(static_cast<int>(est.clone_poses().size()) == est.options().state.max_clones);
  CHECK(est.clone_poses().rbegin()->first == 3500000);
  CHECK_FALSE(est.diverged());
}

// The EuRoC start of `vins`: the player's IMU from the real slice fed to the
// estimator configured by config/vins_euroc.yaml (init.mode: static) must
// initialise at rest, with roll/pitch and gyro bias matching the slice's
// ground truth. Exits with ctest's skip code (77) without VIMOT_DATA_DIR.
#include "tests/drivers/euroc_player/slice_test_main.h"

#include <cmath>
#include <map>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/estimator/vins_config.h"
#include "common/math/quat.h"
#include "common/time/utime.h"
#include "drivers/euroc_player/euroc_player.h"

namespace {

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

TEST_CASE("static initialisation on the slice's IMU agrees with its ground truth", "[euroc][data]") {
  const vimot::estimator::VioOptions options =
      vimot::estimator::load_vio_options(std::string(VIMOT_SOURCE_DIR) + "/config/vins_euroc.yaml");
  REQUIRE(options.init_mode == vimot::estimator::InitMode::kStatic);
  vimot::estimator::VioEstimator estimator(options);

  vimot::euroc::PlayerOptions player_options;
  player_options.dataset = slice_dir();
  player_options.groundtruth_file = slice_dir() + "/groundtruth/V1_01_easy.csv";
  vimot::euroc::EurocPlayer player(player_options);
  std::map<int64_t, vimot::GroundTruth> truth;
  std::vector<vimot::ImuData> fed;
  while (auto e = player.next()) {
    if (const auto* g = std::get_if<vimot::GroundTruth>(&*e)) truth[g->utime] = *g;
    const auto* imu = std::get_if<vimot::ImuData>(&*e);
    if (imu && !estimator.initialized()) {
      fed.push_back(*imu);
      estimator.feed_imu(*imu);
    }
  }
  REQUIRE(estimator.initialized());
  const int64_t t_init = estimator.state_utime();
  // It starts as soon as one window of IMU exists (the slice has no IMU
  // before its first image).
  CHECK(vimot::utime_to_seconds(t_init - fed.front().utime) == Approx(options.static_init.window_s).margin(0.006));
  // The window ends on a camera time, where the slice has ground truth.
  REQUIRE(truth.count(t_init) == 1);
  const vimot::GroundTruth& gt_end = truth.at(t_init);
  const vimot::GroundTruth& gt_begin = truth.begin()->second;
  const vimot::estimator::ImuValue x = estimator.imu_value();

  const Eigen::Matrix3d R_est = vimot::quat_to_rot(x.q_GtoI);
  const Eigen::Matrix3d R_gt = vimot::quat_to_rot(gt_end.q_GtoI);
  const Eigen::Vector3d g_in_G(0.0, 0.0, options.static_init.gravity_magnitude);
  // Up (G's z) seen in I. At rest the accelerometer reads R_GtoI g + b_a, so
  // an initialiser that takes b_a = 0 tilts by the bias's share across
  // gravity; the truth's bias predicts where it must point.
  const Eigen::Vector3d up_est = R_est * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up_gt = R_gt * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up_predicted = (R_gt * g_in_G + gt_end.bias_accel).normalized();
  const double tilt_from_bias = angle_between(up_gt, up_predicted);
  const double error_vs_truth = angle_between(up_est, up_gt);
  const double error_vs_predicted = angle_between(up_est, up_predicted);
  // The rotors run while the vehicle sits on the ground: the accelerometer
  // vibrates far above its datasheet noise. The standard error of the
  // window's means, from the samples' own spread, is what averaging leaves.
  Eigen::Vector3d a_mean = Eigen::Vector3d::Zero(), w_mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& m : fed) {
    if (m.utime < t_init - vimot::seconds_to_utime(options.static_init.window_s)) continue;
    a_mean += m.a_IinI;
    w_mean += m.w_IinI;
    ++n;
  }
  a_mean /= n;
  w_mean /= n;
  double a_var = 0.0, w_var = 0.0;
  for (const auto& m : fed) {
    if (m.utime < t_init - vimot::seconds_to_utime(options.static_init.window_s)) continue;
    a_var += (m.a_IinI - a_mean).squaredNorm();
    w_var += (m.w_IinI - w_mean).squaredNorm();
  }
  const double a_sem = std::sqrt(a_var / (n - 1) / n);  // all three axes together
  const double w_sem = std::sqrt(w_var / (n - 1) / n);
  const double tilt_noise = a_sem / options.static_init.gravity_magnitude;
  // The vehicle is not perfectly still: the truth's own rotation over the
  // window bounds what a mean over it can miss.
  const double rotation_in_window =
      vimot::rotation_angle_between(vimot::quat_to_rot(gt_begin.q_GtoI), R_gt);
  INFO("tilt: error vs truth " << error_vs_truth * 180 / M_PI << " deg, predicted by b_a " << tilt_from_bias * 180 / M_PI
                               << " deg, error vs prediction " << error_vs_predicted * 180 / M_PI
                               << " deg; standard error " << tilt_noise * 180 / M_PI << " deg; truth rotates "
                               << rotation_in_window * 180 / M_PI << " deg in the window");
  CHECK(error_vs_predicted < 3.0 * tilt_noise + rotation_in_window);
  // The window vibrates but does not move: the estimator accepted it.
  CHECK(std::sqrt(a_var / n) < options.static_init.max_accel_std);

  // Gyro bias: the mean rate over the window, off by the mean's standard
  // error and by the truth's own mean rotation rate.
  const double mean_rate = rotation_in_window / options.static_init.window_s;
  const double bg_error = (x.bg - gt_end.bias_gyro).norm();
  INFO("gyro bias: estimate " << x.bg.transpose() << ", truth " << gt_end.bias_gyro.transpose() << ", error "
                              << bg_error << " rad/s; standard error " << w_sem << ", truth's mean rate " << mean_rate);
  CHECK(bg_error < 3.0 * w_sem + mean_rate);
  // The estimate is far better than not estimating the bias at all.
  CHECK(bg_error < 0.1 * gt_end.bias_gyro.norm());
  // Static start: at rest at the origin, with the accelerometer bias unknown.
  CHECK(x.v_IinG.isZero());
  CHECK(x.p_IinG.isZero());
  CHECK(x.ba.isZero());
  // The config's initial sigmas cover the start's actual errors (3σ; the
  // bias errors are 3-vectors of isotropic σ).
  CHECK(error_vs_truth < 3.0 * options.init_sigmas.theta_rp);
  CHECK(bg_error < 3.0 * std::sqrt(3.0) * options.init_sigmas.bg);
  CHECK(gt_end.bias_accel.norm() < 3.0 * std::sqrt(3.0) * options.init_sigmas.ba);
  CHECK(gt_end.v_IinG.norm() < 3.0 * std::sqrt(3.0) * options.init_sigmas.v);
  WARN("static init on the slice: tilt error " << error_vs_truth * 180 / M_PI << " deg (b_a alone predicts "
                                               << tilt_from_bias * 180 / M_PI << " deg), gyro bias error "
                                               << bg_error << " rad/s");
}

#include <catch2/catch.hpp>

#include <random>

#include "common/estimator/static_initializer.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::estimator;

namespace {

// 200 Hz samples at rest with attitude R_GtoI, gyro bias bg, ADIS16448 noise;
// `shake` adds a sinusoidal acceleration (m/s²).
std::vector<ImuData> static_data(const Eigen::Matrix3d& R_GtoI, const Eigen::Vector3d& bg, double seconds,
                                 double shake, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  const double dt = 0.005;
  const double sg = 1.6968e-04 / std::sqrt(dt), sa = 2.0e-3 / std::sqrt(dt);
  std::vector<ImuData> out;
  for (int i = 0; i < static_cast<int>(seconds / dt); ++i) {
    ImuData d;
    d.utime = 1000000 + i * 5000;
    const double t = i * dt;
    const Eigen::Vector3d a_G(shake * std::sin(2 * M_PI * 1.5 * t), shake * std::cos(2 * M_PI * 1.1 * t), 0.0);
    d.a_IinI = R_GtoI * (a_G + Eigen::Vector3d(0, 0, 9.81)) + sa * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    d.w_IinI = bg + sg * Eigen::Vector3d(n01(rng), n01(rng), n01(rng));
    out.push_back(d);
  }
  return out;
}

}  // namespace

TEST_CASE("Static initialisation recovers gravity direction and gyro bias", "[static_init]") {
  const Eigen::Matrix3d R_GtoI = exp_so3(Eigen::Vector3d(0.15, -0.25, 1.2));
  const Eigen::Vector3d bg(0.004, -0.0025, 0.0031);
  StaticInitializer init{StaticInitOptions{}};
  ImuValue x;
  int64_t t = 0;
  const auto data = static_data(R_GtoI, bg, 1.5, 0.0, 1);
  for (size_t i = 0; i < data.size(); ++i) {
    init.feed_imu(data[i]);
    if (i == 50) CHECK(init.try_initialize(&x, &t) == StaticInitStatus::kNotEnoughData);
  }
  double accel_std = 0.0;
  REQUIRE(init.try_initialize(&x, &t, &accel_std) == StaticInitStatus::kReady);
  CHECK(t == data.back().utime);
  CHECK(accel_std < 0.05);
  const Eigen::Matrix3d R_est = quat_to_rot(x.q_GtoI);
  const Eigen::Vector3d up_true = R_GtoI * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up_est = R_est * Eigen::Vector3d::UnitZ();
  CHECK(std::acos(std::min(1.0, up_true.dot(up_est))) < 1e-3);  // rad
  // Gyro bias: white noise 0.0024 rad/s per sample, 200 samples → 1.7e-4.
  CHECK((x.bg - bg).norm() < 1e-3);
  CHECK(x.v_IinG.norm() == 0.0);
  CHECK(x.ba.norm() == 0.0);
  // Yaw 0: the IMU x axis projected on the horizontal is G x.
  const Eigen::Vector3d x_I_in_G = R_est.transpose() * Eigen::Vector3d::UnitX();
  CHECK(std::abs(x_I_in_G.y()) < 1e-12);
  CHECK(x_I_in_G.x() > 0.0);
}

TEST_CASE("Static initialisation waits while the platform moves", "[static_init]") {
  StaticInitializer init{StaticInitOptions{}};
  for (const auto& d : static_data(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero(), 1.5, 1.0, 2)) init.feed_imu(d);
  ImuValue x;
  int64_t t = 0;
  double accel_std = 0.0;
  CHECK(init.try_initialize(&x, &t, &accel_std) == StaticInitStatus::kMoving);
  CHECK(accel_std > 0.1);
}

#include "common/estimator/static_initializer.h"

#include <cmath>
#include <stdexcept>

#include "common/math/quat.h"
#include "common/time/utime.h"

namespace vimot {
namespace estimator {

const char* to_string(StaticInitStatus status) {
  switch (status) {
    case StaticInitStatus::kNotEnoughData: return "not enough IMU data";
    case StaticInitStatus::kMoving: return "moving (accelerometer variance above threshold)";
    case StaticInitStatus::kBadGravity: return "mean specific force does not match gravity";
    case StaticInitStatus::kReady: return "ready";
  }
  return "unknown";
}

StaticInitializer::StaticInitializer(const StaticInitOptions& options) : options_(options) {
  if (!(options_.window_s > 0.0) || !(options_.max_accel_std > 0.0) || !(options_.gravity_magnitude > 0.0) ||
      !(options_.max_gravity_error > 0.0)) {
    throw std::invalid_argument("StaticInitOptions: window_s, max_accel_std, gravity_magnitude and "
                                "max_gravity_error must be positive");
  }
}

void StaticInitializer::feed_imu(const ImuData& imu) {
  if (!imu.w_IinI.allFinite() || !imu.a_IinI.allFinite()) return;
  if (!buffer_.empty() && imu.utime <= buffer_.back().utime) return;
  buffer_.push_back(imu);
  // Keep a little more than one window.
  const int64_t keep = seconds_to_utime(2.0 * options_.window_s);
  while (!buffer_.empty() && buffer_.back().utime - buffer_.front().utime > keep) buffer_.pop_front();
}

StaticInitStatus StaticInitializer::try_initialize(ImuValue* value, int64_t* utime, double* accel_std) const {
  if (buffer_.size() < 10) return StaticInitStatus::kNotEnoughData;
  const int64_t t_end = buffer_.back().utime;
  const int64_t t_begin = t_end - seconds_to_utime(options_.window_s);
  if (buffer_.front().utime > t_begin) return StaticInitStatus::kNotEnoughData;
  Eigen::Vector3d a_mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d w_mean = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& d : buffer_) {
    if (d.utime < t_begin) continue;
    a_mean += d.a_IinI;
    w_mean += d.w_IinI;
    ++n;
  }
  a_mean /= n;
  w_mean /= n;
  double var = 0.0;
  for (const auto& d : buffer_) {
    if (d.utime >= t_begin) var += (d.a_IinI - a_mean).squaredNorm();
  }
  const double std_a = std::sqrt(var / n);
  if (accel_std) *accel_std = std_a;
  if (std_a > options_.max_accel_std) return StaticInitStatus::kMoving;
  if (std::abs(a_mean.norm() - options_.gravity_magnitude) > options_.max_gravity_error) {
    return StaticInitStatus::kBadGravity;
  }
  const Eigen::Vector3d z = a_mean.normalized();
  Eigen::Vector3d e = Eigen::Vector3d::UnitX();
  if (std::abs(z.dot(e)) > 0.9) e = Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = (e - z * z.dot(e)).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R_GtoI;
  R_GtoI << x, y, z;
  ImuValue v;
  v.q_GtoI = rot_to_quat(R_GtoI);
  v.bg = w_mean;
  *value = v;
  *utime = t_end;
  return StaticInitStatus::kReady;
}

}  // namespace estimator
}  // namespace vimot

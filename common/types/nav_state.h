#pragma once
// The robot's estimated navigation state as the estimators publish it
// (VINS_STATE, NAV_STATE). No LCM here.

#include <Eigen/Core>
#include <cstdint>

namespace vimot {

struct NavState {
  int64_t utime{0};   // µs
  bool updated{false};  // true right after a camera update, false for IMU-rate propagation
  Eigen::Vector4d q_GtoI{0.0, 0.0, 0.0, 1.0};          // JPL [qx qy qz qw]
  Eigen::Vector3d p_IinG{Eigen::Vector3d::Zero()};      // m
  Eigen::Vector3d v_IinG{Eigen::Vector3d::Zero()};      // m/s
  Eigen::Vector3d bias_gyro{Eigen::Vector3d::Zero()};   // rad/s
  Eigen::Vector3d bias_accel{Eigen::Vector3d::Zero()};  // m/s²
  /// Error-state covariance, order [δθ (left, R = exp(-δθ) R̂), δp, δv, δbg, δba].
  Eigen::Matrix<double, 15, 15> covariance{Eigen::Matrix<double, 15, 15>::Zero()};
  int num_clones{0};
  int num_slam_features{0};
  int num_msckf_features{0};
};

}  // namespace vimot

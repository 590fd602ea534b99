#pragma once
// The moving target's estimate as the target filter publishes it
// (TARGET_STATE, TARGET_PREDICTION; lcmtypes/vimot_target_state_t.lcm,
// vimot_target_prediction_t.lcm). No LCM here.

#include <Eigen/Core>
#include <cstdint>

namespace vimot {

/// Which target pose is the filter's state (and the frame of the covariance).
enum class TargetFrame : int8_t {
  kGlobal = 0,  // [q_GtoT, p_TinG]
  kLocal = 1,   // [q_ItoT, p_TinI], I the IMU at utime (robot-centric)
};

struct TargetStateEstimate {
  int64_t utime{0};  // µs, a camera utime
  TargetFrame representation{TargetFrame::kLocal};
  Eigen::Vector4d q_ItoT{0.0, 0.0, 0.0, 1.0};      // JPL [qx qy qz qw]
  Eigen::Vector3d p_TinI{Eigen::Vector3d::Zero()};  // m
  Eigen::Vector4d q_GtoT{0.0, 0.0, 0.0, 1.0};      // JPL
  Eigen::Vector3d p_TinG{Eigen::Vector3d::Zero()};  // m
  Eigen::Vector3d v_TinT{Eigen::Vector3d::Zero()};  // m/s, in T
  Eigen::Vector3d w_TinT{Eigen::Vector3d::Zero()};  // rad/s, in T
  /// [δθ_T, δp_T, δv, δw] in `representation` (see the .lcm file).
  Eigen::Matrix<double, 12, 12> covariance{Eigen::Matrix<double, 12, 12>::Zero()};
  int num_target_points{0};
  /// Times the filter started the target (a change: a new target frame).
  int start_count{0};
};

struct TargetPosePrediction {
  int64_t utime{0};             // µs, of the source TargetStateEstimate
  int64_t prediction_utime{0};  // µs, the time predicted for
  Eigen::Vector4d q_GtoT{0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d p_TinG{Eigen::Vector3d::Zero()};
  /// Relative to the robot pose at utime (the robot is not predicted).
  Eigen::Vector4d q_ItoT{0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d p_TinI{Eigen::Vector3d::Zero()};
  /// [δθ_T (in T), δp_T (in G)] of q_GtoT, p_TinG.
  Eigen::Matrix<double, 6, 6> covariance{Eigen::Matrix<double, 6, 6>::Zero()};
};

}  // namespace vimot

#pragma once
// True robot (and target) state at one time: what the simulator knows and
// the evaluators compare against. No LCM here.

#include <Eigen/Core>
#include <cstdint>

namespace vimot {

struct GroundTruth {
  int64_t utime{0};                                    // µs
  Eigen::Vector4d q_GtoI{0.0, 0.0, 0.0, 1.0};          // JPL [qx qy qz qw]
  Eigen::Vector3d p_IinG{Eigen::Vector3d::Zero()};      // m
  Eigen::Vector3d v_IinG{Eigen::Vector3d::Zero()};      // m/s, in G
  Eigen::Vector3d w_IinI{Eigen::Vector3d::Zero()};      // rad/s, in I
  Eigen::Vector3d a_IinG{Eigen::Vector3d::Zero()};      // m/s², in G (kinematic, no gravity)
  Eigen::Vector3d bias_gyro{Eigen::Vector3d::Zero()};   // rad/s, in I
  Eigen::Vector3d bias_accel{Eigen::Vector3d::Zero()};  // m/s², in I
  bool has_target{false};
  Eigen::Vector4d q_GtoT{0.0, 0.0, 0.0, 1.0};          // JPL [qx qy qz qw]
  Eigen::Vector3d p_TinG{Eigen::Vector3d::Zero()};      // m, the target frame origin
  Eigen::Vector3d v_TinT{Eigen::Vector3d::Zero()};      // m/s, in T
  Eigen::Vector3d w_TinT{Eigen::Vector3d::Zero()};      // rad/s, in T
};

}  // namespace vimot

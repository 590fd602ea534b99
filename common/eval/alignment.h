#pragma once
// Trajectory error after a 4-DoF alignment (yaw about G's z and a
// translation), the "posyaw" alignment OpenVINS's ov_eval applies to VIO
// before its ATE: it removes the unobservable directions (global yaw and
// position), so it measures drift shape, not the absolute error. Only for
// comparing with figures published that way; vimot's own metric is the
// unaligned RMSE (metrics.h). No LCM here.

#include <Eigen/Core>
#include <vector>

namespace vimot {
namespace eval {

struct PosePair {
  Eigen::Vector4d q_GtoI_est{0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d p_IinG_est{Eigen::Vector3d::Zero()};
  Eigen::Vector4d q_GtoI_true{0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d p_IinG_true{Eigen::Vector3d::Zero()};
};

struct YawAlignment {
  double yaw{0.0};                               // rad, about G's z
  Eigen::Vector3d t{Eigen::Vector3d::Zero()};    // m
  /// Aligned estimate: p' = Rz(yaw) p + t, R_ItoG' = Rz(yaw) R_ItoG.
};

/// Least-squares yaw and translation taking the estimated positions onto the
/// true ones (closed form: centred x-y cross terms give the yaw).
YawAlignment align_position_yaw(const std::vector<PosePair>& pairs);

struct AlignedErrors {
  YawAlignment alignment;
  double ate_position_m{0.0};       // RMSE of |p_true − p'|
  double ate_orientation_deg{0.0};  // RMSE of the rotation angle between R_true and R'
  int count{0};
};

/// ATE of position and orientation after align_position_yaw (zeros if empty).
AlignedErrors aligned_errors(const std::vector<PosePair>& pairs);

}  // namespace eval
}  // namespace vimot

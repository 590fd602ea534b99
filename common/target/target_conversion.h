#pragma once
// Conversions of the target state between the local (R = I) and global
// (R = G) representations, given the IMU pose (R_GtoI, p_IinG) at the same
// time, and their error-state Jacobians (left errors, see target_types.h).
//
// local → global:
//   R_GtoT = R_ItoT R_GtoI,    p_TinG = p_IinG + R_GtoIᵀ p_TinI,   v, w unchanged (in T)
//   δθ_G = δθ_L + R̂_ItoT δθ_I
//   δp_G = δp_I + R̂_GtoIᵀ δp_L − R̂_GtoIᵀ [p̂_TinI ×] δθ_I
// global → local:
//   R_ItoT = R_GtoT R_GtoIᵀ,   p_TinI = R_GtoI (p_TinG − p_IinG)
//   δθ_L = δθ_G − R̂_ItoT δθ_I
//   δp_L = R̂_GtoI (δp_G − δp_I) + [p̂_TinI ×] δθ_I
// J_pose is w.r.t. the IMU pose error [δθ_I, δp_I] (12×6), J_target w.r.t.
// the 12-dim target error (12×12). For a target pose clone use the top-left
// 6×6 blocks.

#include <Eigen/Core>

#include "common/target/target_types.h"

namespace vimot {
namespace target {

/// Global target from the IMU pose and the local target; Jacobians optional.
TargetValue local_to_global(const PoseValue& imu_pose, const TargetValue& x_local, Matrix12x6d* J_pose = nullptr,
                            Matrix12d* J_target = nullptr);

/// Local target from the IMU pose and the global target; Jacobians optional.
TargetValue global_to_local(const PoseValue& imu_pose, const TargetValue& x_global, Matrix12x6d* J_pose = nullptr,
                            Matrix12d* J_target = nullptr);

/// Covariance (12×12) of the global target given the joint covariance of
/// [δθ_I, δp_I, δx_L] (18×18): J P Jᵀ with J = [J_pose, J_target].
Matrix12d local_to_global_covariance(const PoseValue& imu_pose, const TargetValue& x_local,
                                     const Eigen::Matrix<double, 18, 18>& P_pose_target);

/// Covariance (12×12) of the local target given the joint covariance of
/// [δθ_I, δp_I, δx_G] (18×18).
Matrix12d global_to_local_covariance(const PoseValue& imu_pose, const TargetValue& x_global,
                                     const Eigen::Matrix<double, 18, 18>& P_pose_target);

}  // namespace target
}  // namespace vimot

#pragma once
// Camera measurements of a point p_FinT rigidly attached to the target
// (paper Eq. 7–9), in undistorted normalized coordinates:
//   z = Π(p_FinC) + n,  Π([x y z]) = [x/z, y/z]
// Global (Eq. 8):  p_FinC = R_ItoC R_GtoI (R_GtoTᵀ p_FinT + p_TinG − p_IinG) + p_IinC
// Local  (Eq. 9):  p_FinC = R_ItoC (R_ItoTᵀ p_FinT + p_TinI) + p_IinC
// with the IMU pose (or IMU clone) and the target pose (or target clone) at
// the image time. Left errors R = Exp(−δθ) R̂ for both poses:
//   Global, with p_FinG = R̂_GtoTᵀ p_FinT + p̂_TinG:
//     ∂p_FinC/∂δθ_I = R_ItoC [R̂_GtoI (p_FinG − p̂_IinG) ×],   ∂p_FinC/∂δp_I = −R_ItoC R̂_GtoI
//     ∂p_FinC/∂δθ_T = −R_ItoC R̂_GtoI R̂_GtoTᵀ [p_FinT ×],     ∂p_FinC/∂δp_T = R_ItoC R̂_GtoI
//     ∂p_FinC/∂p_FinT = R_ItoC R̂_GtoI R̂_GtoTᵀ
//   Local (no IMU dependence):
//     ∂p_FinC/∂δθ_T = −R_ItoC R̂_ItoTᵀ [p_FinT ×],  ∂p_FinC/∂δp_T = R_ItoC,
//     ∂p_FinC/∂p_FinT = R_ItoC R̂_ItoTᵀ
//   ∂z/∂p_FinC = (1/z) [1 0 −x/z; 0 1 −y/z].
// The static-scene point measurement is the estimator's (measurement_model.h).

#include <Eigen/Core>

#include "common/target/target_types.h"

namespace vimot {
namespace target {

/// Camera extrinsics: p_C = R_ItoC p_I + p_IinC.
struct CameraExtrinsics {
  Eigen::Matrix3d R_ItoC{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_IinC{Eigen::Vector3d::Zero()};
};

/// Prediction of one target-point observation and its Jacobians.
struct TargetPointPrediction {
  bool valid{false};                          // depth > min_depth (Jacobians still filled)
  Eigen::Vector3d p_FinC{Eigen::Vector3d::Zero()};
  Eigen::Vector2d z{Eigen::Vector2d::Zero()};
  Eigen::Matrix<double, 2, 6> H_imu_pose{Eigen::Matrix<double, 2, 6>::Zero()};     // [δθ_I δp_I]; zero for local
  Eigen::Matrix<double, 2, 6> H_target_pose{Eigen::Matrix<double, 2, 6>::Zero()};  // [δθ_T δp_T]
  Eigen::Matrix<double, 2, 3> H_point{Eigen::Matrix<double, 2, 3>::Zero()};        // p_FinT
};

/// Re-linearisation of an in-state target point whose linearisation point
/// moves from p_lin to p_new, with its covariance carried along the
/// unobservable directions. The point's new error is
///   δp' = δp + [(p_new − p_lin)×] δθ_TrelI,  δθ_TrelI = δθ_T − R_ItoT δθ_I
/// (T's rotation error relative to the IMU; local: δθ_T itself), J over
/// [δθ_T δp_T (target pose); δθ_I δp_I (IMU pose, global only); δp], 3×9
/// local, 3×15 global. It takes the target gauge's point rows [p_lin×]α − t
/// to [p_new×]α − t and keeps the world yaw's and position's at 0 (T and I
/// turn together), so Jacobians at p_new annihilate the directions the
/// covariance holds, as the first estimate's did. R_ItoT at the poses'
/// first estimates, where the covariance holds them
/// (StateHelper::transform_variable; docs/target_model.md).
Eigen::MatrixXd point_relinearization(TargetRepresentation representation, const Eigen::Matrix3d& R_ItoT,
                                      const Eigen::Vector3d& p_lin, const Eigen::Vector3d& p_new);

/// p_FinC of a target point (Eq. 8 or 9). imu_pose is ignored for kLocal.
Eigen::Vector3d target_point_in_camera(TargetRepresentation representation, const PoseValue& imu_pose,
                                       const PoseValue& target_pose, const Eigen::Vector3d& p_FinT,
                                       const CameraExtrinsics& cam);

/// z = Π(p_FinC) and the Jacobians above. target_pose is [q_RtoT, p_TinR]
/// of the target (or target clone) at the image time.
TargetPointPrediction predict_target_point(TargetRepresentation representation, const PoseValue& imu_pose,
                                           const PoseValue& target_pose, const Eigen::Vector3d& p_FinT,
                                           const CameraExtrinsics& cam, double min_depth = 1e-3);

}  // namespace target
}  // namespace vimot

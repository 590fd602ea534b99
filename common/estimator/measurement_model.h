#pragma once
// Camera measurement model of the updaters: normalized image coordinates
//   z = Π(p_FinC) + n,  Π([x y z]) = [x/z, y/z],  n ~ N(0, σ² I),  σ = σ_px / f,
//   p_FinC = R_ItoC R_GtoI (p_FinG − p_IinG) + p_IinC.
// With the left error R_GtoI = Exp(−δθ) R̂_GtoI, the Jacobians are
//   ∂z/∂p_FinC = (1/z) [1 0 −x/z; 0 1 −y/z]
//   ∂p_FinC/∂δθ = R_ItoC [R̂_GtoI (p_FinG − p_IinG) ×]
//   ∂p_FinC/∂δp_IinG = −R_ItoC R̂_GtoI,   ∂p_FinC/∂p_FinG = R_ItoC R̂_GtoI.
// Anchored inverse depth λ = [α β ρ] of a point in anchor camera a of the
// anchor pose A (R_GtoA, p_AinG):
//   p_FinCa = [α β 1]ᵀ/ρ,  p_FinG = p_AinG + R_GtoAᵀ R_ItoCaᵀ (p_FinCa − p_IinCa)
//   ∂p_FinG/∂λ = R_GtoAᵀ R_ItoCaᵀ [1/ρ 0 −α/ρ²; 0 1/ρ −β/ρ²; 0 0 −1/ρ²]
//   ∂p_FinG/∂δθ_A = −R_GtoAᵀ [(R_ItoCaᵀ (p_FinCa − p_IinCa)) ×],  ∂p_FinG/∂δp_AinG = I.

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "common/camera/camera_model.h"

namespace vimot {
namespace estimator {

/// What the updaters need of one camera: fixed extrinsics and noise.
///
/// Noise: the measurement is the undistorted (normalized) point of a pixel
/// with N(0, σ_px² I) noise, so to first order its covariance is
/// σ_px² D⁻¹ D⁻ᵀ with D = ∂pixel/∂normalized (distortion and focal length)
/// at the measured point. The updaters whiten each observation with
/// W = D / σ_px (rows and residual multiplied by W, noise then N(0, I)).
/// Without a camera model (model == nullptr), D = f I: σ = σ_px / f.
struct CameraInfo {
  Eigen::Matrix3d R_ItoC{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_IinC{Eigen::Vector3d::Zero()};
  double sigma_normalized{1.0 / 450.0};            // σ_px / f (normalized units)
  double sigma_px{1.0};                            // pixels
  std::shared_ptr<const CameraModel> model;        // for the distortion Jacobian

  static CameraInfo from_calibration(const CameraCalibration& calibration, double sigma_px);

  /// Whitening W of an observation at normalized point uv (see above).
  Eigen::Matrix2d whitening(const Eigen::Vector2d& uv) const {
    if (!model) return Eigen::Matrix2d::Identity() / sigma_normalized;
    return model->distort_jacobian(uv) / sigma_px;
  }
};

/// Π(p) = [x/z, y/z].
inline Eigen::Vector2d project(const Eigen::Vector3d& p) { return p.head<2>() / p.z(); }

/// ∂Π/∂p.
Eigen::Matrix<double, 2, 3> project_jacobian(const Eigen::Vector3d& p);

/// p_FinC of a global point seen from the IMU pose (R_GtoI, p_IinG).
Eigen::Vector3d point_in_camera(const Eigen::Matrix3d& R_GtoI, const Eigen::Vector3d& p_IinG,
                                const Eigen::Vector3d& p_FinG, const CameraInfo& cam);

/// Predicted z and its Jacobians w.r.t. the pose error [δθ δp] (2×6) and
/// the global point (2×3); pass nullptr for unneeded outputs.
Eigen::Vector2d global_point_measurement(const Eigen::Matrix3d& R_GtoI, const Eigen::Vector3d& p_IinG,
                                         const Eigen::Vector3d& p_FinG, const CameraInfo& cam,
                                         Eigen::Matrix<double, 2, 6>* H_pose, Eigen::Matrix<double, 2, 3>* H_f);

/// p_FinG of an anchored inverse-depth point; Jacobians w.r.t. λ (3×3) and
/// the anchor pose error [δθ_A δp_A] (3×6), nullptr if unneeded.
Eigen::Vector3d anchored_to_global(const Eigen::Vector3d& lambda, const Eigen::Matrix3d& R_GtoA,
                                   const Eigen::Vector3d& p_AinG, const CameraInfo& anchor_cam,
                                   Eigen::Matrix3d* dpf_dlambda, Eigen::Matrix<double, 3, 6>* dpf_danchor);

/// λ of a global point in the anchor camera (inverse of anchored_to_global).
Eigen::Vector3d global_to_anchored(const Eigen::Vector3d& p_FinG, const Eigen::Matrix3d& R_GtoA,
                                   const Eigen::Vector3d& p_AinG, const CameraInfo& anchor_cam);
/// ... and its Jacobians w.r.t. the global point (3×3) and the anchor pose
/// error [δθ_A δp_A] (3×6), nullptr if unneeded. With p_FinCa = [x y z]:
///   ∂λ/∂p_FinCa = [1/z 0 −x/z²; 0 1/z −y/z²; 0 0 −1/z²]
///   ∂p_FinCa/∂p_FinG = R_ItoCa R_GtoA,  ∂p_FinCa/∂δθ_A = R_ItoCa [R_GtoA (p_FinG − p_AinG)×],
///   ∂p_FinCa/∂δp_A = −R_ItoCa R_GtoA.
Eigen::Vector3d global_to_anchored(const Eigen::Vector3d& p_FinG, const Eigen::Matrix3d& R_GtoA,
                                   const Eigen::Vector3d& p_AinG, const CameraInfo& anchor_cam,
                                   Eigen::Matrix3d* dl_dpf, Eigen::Matrix<double, 3, 6>* dl_danchor);

/// Anchor change (OpenVINS's change_anchor): the same point re-expressed in
/// a new anchor camera b of the pose B,
///   λ_B = g(λ_A, A, B) = global_to_anchored(anchored_to_global(λ_A, A), B).
/// J (3×15) is its Jacobian w.r.t. the errors [λ̃_A, δθ_A, δp_A, δθ_B, δp_B]:
///   J = [G_f F_λ, G_f F_A, G_B]  with F = ∂p_FinG/∂(λ_A, A), G = ∂λ_B/∂(p_FinG, B).
/// Returns λ_B (z of the point in camera b must be > 0: the caller checks).
Eigen::Vector3d change_anchor(const Eigen::Vector3d& lambda_A, const Eigen::Matrix3d& R_GtoA,
                              const Eigen::Vector3d& p_AinG, const CameraInfo& cam_a, const Eigen::Matrix3d& R_GtoB,
                              const Eigen::Vector3d& p_BinG, const CameraInfo& cam_b,
                              Eigen::Matrix<double, 3, 15>* J);

}  // namespace estimator
}  // namespace vimot

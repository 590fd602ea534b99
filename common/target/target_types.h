#pragma once
// Value types of the target (moving rigid body) models; see docs/target_model.md.
//
// Target state (Eckenhoff et al., "Schmidt-EKF-based Visual-Inertial Moving
// Object Tracking", Sec. III):
//   x_T = [q_RtoT, p_TinR, v_TinT, w_TinT]
// with R = G (global representation) or R = I (local / robot-centric, R is
// the IMU frame at the same time). q_RtoT is a JPL quaternion
// (common/math/quat.h). The error state (12) is
//   δx_T = [δθ_T, δp_T, δv_T, δw_T],   R_RtoT = Exp(−δθ_T) R̂_RtoT,
// and additive for p, v, w; x = x̂ ⊞ δx.

#include <Eigen/Core>

#include "common/estimator/types.h"

namespace vimot {
namespace target {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Matrix12x15d = Eigen::Matrix<double, 12, 15>;
using Matrix12x6d = Eigen::Matrix<double, 12, 6>;
using Matrix15d = Eigen::Matrix<double, 15, 15>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

/// Frame the target pose is expressed in.
enum class TargetRepresentation {
  kGlobal,  // R = G: [q_GtoT, p_TinG, v_TinT, w_TinT]
  kLocal,   // R = I: [q_ItoT, p_TinI, v_TinT, w_TinT], I the current IMU frame
};
const char* to_string(TargetRepresentation representation);

/// A pose [q_AtoB (JPL), p_BinA], error [δθ, δp] with R_AtoB = Exp(−δθ) R̂_AtoB.
/// Used for the IMU pose (q_GtoI, p_IinG) and the target pose (q_RtoT, p_TinR).
struct PoseValue {
  Eigen::Vector4d q{0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d p{Eigen::Vector3d::Zero()};

  Eigen::Matrix3d R() const;
};

/// The IMU pose [q_GtoI, p_IinG] of an estimator ImuValue.
PoseValue imu_pose(const estimator::ImuValue& imu);

/// Target value x_T (see the header note).
struct TargetValue {
  Eigen::Vector4d q_RtoT{0.0, 0.0, 0.0, 1.0};        // JPL
  Eigen::Vector3d p_TinR{Eigen::Vector3d::Zero()};   // m
  Eigen::Vector3d v_TinT{Eigen::Vector3d::Zero()};   // m/s, target linear velocity in T
  Eigen::Vector3d w_TinT{Eigen::Vector3d::Zero()};   // rad/s, target angular velocity in T

  Eigen::Matrix3d R_RtoT() const;
  PoseValue pose() const { return PoseValue{q_RtoT, p_TinR}; }

  /// [q_RtoT; p_TinR; v_TinT; w_TinT] (13).
  Eigen::Matrix<double, 13, 1> to_vector() const;
  static TargetValue from_vector(const Eigen::Matrix<double, 13, 1>& x);
};

/// x ⊞ δ: q ← quat_boxplus(q, δθ) (R = Exp(−δθ) R̂), the rest additive.
TargetValue boxplus(const TargetValue& x, const Vector12d& dx);
/// y ⊟ x: the δ with y = x ⊞ δ (δθ = −Log(R_y R_xᵀ)).
Vector12d boxminus(const TargetValue& y, const TargetValue& x);
PoseValue boxplus(const PoseValue& x, const Vector6d& dx);
Vector6d boxminus(const PoseValue& y, const PoseValue& x);

/// Continuous-time target noise: v̇_TinT = n_v, ẇ_TinT = n_w, white, with
/// per-axis densities (in T) sigma_v (m/s²/√Hz) and sigma_w (rad/s²/√Hz):
///   E[n(t) n(s)ᵀ] = Q_c δ(t−s),  Q_c = diag(sigma_v², sigma_w²).
struct TargetNoise {
  Eigen::Vector3d sigma_v{Eigen::Vector3d::Constant(0.1)};
  Eigen::Vector3d sigma_w{Eigen::Vector3d::Constant(0.1)};

  /// Same density on every axis.
  static TargetNoise isotropic(double sigma_v, double sigma_w);
  /// Planar target (paper Sec. IV): random walk only on v_x, v_y and w_z.
  static TargetNoise planar(double sigma_v_xy, double sigma_w_z);
  /// Q_c (6×6) of [n_v; n_w].
  Matrix6d Qc() const;
  /// All densities finite and >= 0.
  bool valid() const;
};

}  // namespace target
}  // namespace vimot

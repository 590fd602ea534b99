#pragma once
// The one quaternion / SO(3) helper set of vimot.
//
// Convention (JPL, Trawny & Roumeliotis, "Indirect Kalman Filter for 3D
// Attitude Estimation", 2005 — the convention of both papers and OpenVINS):
//  * A quaternion is an Eigen::Vector4d q = [qx qy qz qw]: vector part first,
//    scalar last, unit norm, qw >= 0 after normalisation.
//  * q_AtoB parametrises the rotation matrix R_AtoB that takes a vector
//    expressed in frame A into frame B:  v_B = R_AtoB * v_A.
//      R(q) = (2 qw^2 - 1) I - 2 qw [qv x] + 2 qv qv^T
//  * Products compose like matrices:  R(q ⊗ p) = R(q) R(p), so
//      q_AtoC = q_BtoC ⊗ q_AtoB.
//  * Errors are left-multiplicative:  q = δq ⊗ q̂ with δq ≈ [δθ/2; 1], so
//      R = (I - [δθ x]) R̂  ≈ exp(-δθ) R̂.
//  * Time derivative:  q̇_GtoI = ½ Ω(ω) q_GtoI, ω the body rate in I.
//
// Text files (TUM format) carry the body-to-world Hamilton quaternion
// qx qy qz qw. A Hamilton quaternion of R equals the JPL quaternion of R^T,
// so the TUM components of q_ItoG (Hamilton) are exactly the components of
// q_GtoI (JPL); hamilton_ItoG_to_jpl_GtoI() is the one place that says so.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace vimot {

/// Skew-symmetric matrix: skew(a) * b = a × b.
Eigen::Matrix3d skew(const Eigen::Vector3d& a);

/// Inverse of skew() on its (anti-symmetric part of the) argument.
Eigen::Vector3d vee(const Eigen::Matrix3d& m);

/// SO(3) exponential (Rodrigues): exp_so3(θ) = exp([θ x]).
Eigen::Matrix3d exp_so3(const Eigen::Vector3d& theta);

/// SO(3) logarithm, inverse of exp_so3 for rotation angles in [0, π].
Eigen::Vector3d log_so3(const Eigen::Matrix3d& R);

/// Left Jacobian of SO(3): exp([(θ+δ) x]) ≈ exp([Jl(θ)δ x]) exp([θ x]).
Eigen::Matrix3d jl_so3(const Eigen::Vector3d& theta);

/// Right Jacobian of SO(3): exp([(θ+δ) x]) ≈ exp([θ x]) exp([Jr(θ)δ x]).
Eigen::Matrix3d jr_so3(const Eigen::Vector3d& theta);

/// JPL rotation matrix of a unit quaternion [qx qy qz qw].
Eigen::Matrix3d quat_to_rot(const Eigen::Vector4d& q);

/// JPL quaternion of a rotation matrix (qw >= 0).
Eigen::Vector4d rot_to_quat(const Eigen::Matrix3d& R);

/// JPL product q ⊗ p, with quat_to_rot(q ⊗ p) = quat_to_rot(q) quat_to_rot(p).
Eigen::Vector4d quat_multiply(const Eigen::Vector4d& q, const Eigen::Vector4d& p);

/// Inverse (conjugate) of a unit quaternion.
Eigen::Vector4d quat_inverse(const Eigen::Vector4d& q);

/// Unit quaternion with qw >= 0; throws std::invalid_argument on a zero or
/// non-finite input, since that is never a rotation.
Eigen::Vector4d quat_normalize(const Eigen::Vector4d& q);

/// Ω(ω) with q̇ = ½ Ω(ω) q for JPL q_GtoI and body rate ω in I.
Eigen::Matrix4d omega_matrix(const Eigen::Vector3d& w);

/// Left error quaternion of a small angle: δq ≈ [θ/2; 1], exact and unit:
/// quat_to_rot(small_angle_quat(θ)) = exp_so3(-θ).
Eigen::Vector4d small_angle_quat(const Eigen::Vector3d& theta);

/// Applies a left-multiplicative correction: quat_to_rot(result) =
/// exp_so3(-δθ) quat_to_rot(q). The estimator's ⊞ for quaternions.
Eigen::Vector4d quat_boxplus(const Eigen::Vector4d& q, const Eigen::Vector3d& dtheta);

/// TUM/Hamilton body-to-world [qx qy qz qw] -> JPL q_GtoI (see header note).
Eigen::Vector4d hamilton_ItoG_to_jpl_GtoI(const Eigen::Vector4d& q_hamilton_ItoG);

/// JPL q_GtoI -> TUM/Hamilton body-to-world [qx qy qz qw].
Eigen::Vector4d jpl_GtoI_to_hamilton_ItoG(const Eigen::Vector4d& q_GtoI);

/// Rotation angle (rad, in [0, π]) between two rotations.
double rotation_angle_between(const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb);

}  // namespace vimot

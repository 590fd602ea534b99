#pragma once
// Target motion models of the Schmidt-EKF paper (Eckenhoff et al., Sec. III-A)
// as pure functions; derivations in docs/target_model.md.
//
// State x_T = [q_RtoT, p_TinR, v_TinT, w_TinT], error [δθ_T, δp_T, δv_T, δw_T]
// (R_RtoT = Exp(−δθ_T) R̂_RtoT). Motion: constant local velocities driven by
// white noise, v̇ = n_v, ẇ = n_w (Eq. 6), Q_c = diag(σ_v², σ_w²).
//
// Global (R = G, Eq. 3):  Ṙ_GtoT = −[w×] R_GtoT,   ṗ_TinG = R_GtoTᵀ v.
// Local  (R = I, Eq. 5):  Ṙ_ItoT = −[w×] R_ItoT + R_ItoT [ω_I×],
//                         ṗ_TinI = −[ω_I×] p_TinI + R_ItoTᵀ v − R_GtoI v_IinG,
//   with ω_I = ω_m − b_g − n_g the IMU's true rate.
//
// Discrete step over [t_k, t_k+1], dt (exact for the noise-free model):
//   Global:  R_k+1 = Exp(−w dt) R_k,  p_k+1 = p_k + R_kᵀ Γ1(w, dt) v,  v, w unchanged
//            (Γ1(w, dt) = ∫₀^dt Exp(wτ) dτ, the estimator's gamma integral).
//     Φ_θθ = Exp(−w dt),   Φ_θw = Jr(w dt) dt,
//     Φ_pθ = −R_kᵀ [(Γ1 v)×],  Φ_pv = R_kᵀ Γ1,  Φ_pw = R_kᵀ D1(w, v, dt),
//     Φ_vv = Φ_ww = I,   D1(w, v, dt) = ∂(Γ1(w) v)/∂w = −∫₀^dt Exp(wτ)[v×]Jr(wτ) τ dτ,
//     Q_G = ∫₀^dt M(τ) Q_c M(τ)ᵀ dτ,  M(τ) = ∂x_k+1/∂[v; w] at time τ (the step
//     Jacobian from τ to t_k+1, columns v and w), by composite 4-point
//     Gauss–Legendre quadrature (exact for w = 0; otherwise error O((|w|h)⁸),
//     h the sub-interval with |w|h ≤ 0.25).
//   Local:  the local target is exactly the composition
//            x_L,k+1 = to_local(pose_I,k+1, f_G(to_global(pose_I,k, x_L,k)))
//     so it depends on the IMU only through its poses at t_k and t_k+1:
//       R_ItoT,k+1 = Exp(−w dt) R_ItoT,k R_GtoI,k R_GtoI,k+1ᵀ
//       p_TinI,k+1 = R_GtoI,k+1 [R_GtoI,kᵀ (p_TinI,k + R_ItoT,kᵀ Γ1 v) − (p_IinG,k+1 − p_IinG,k)]
//     With the conversion Jacobians (target_conversion.h) A_L = ∂G/∂L, A_I = ∂G/∂pose_k,
//     B = ∂L'/∂G', C = ∂L'/∂pose_k+1 and the estimator's own IMU step
//     δx_I,k+1 = Φ_II δx_I,k + w_I (cov Q_II):
//       Φ_TT = B Φ_G A_L,   Φ_TI = B Φ_G A_I [I₆ 0] + C Φ_II[0:6, :]
//       Q_TT = B Q_G Bᵀ + C Q_II[0:6,0:6] Cᵀ,   Q_TI = cov(w_T, w_I) = C Q_II[0:6, :]
//     so the joint [x_I; x_T] step is Φ = [[Φ_II, 0], [Φ_TI, Φ_TT]],
//     Q = [[Q_II, Q_TIᵀ], [Q_TI, Q_TT]] (joint_transition()). This holds for a
//     single IMU step or for a whole camera interval (Φ_II, Q_II of
//     Propagator::predict_interval, dt the interval length).

#include <vector>

#include <Eigen/Core>

#include "common/estimator/propagator.h"
#include "common/estimator/types.h"
#include "common/target/target_types.h"

namespace vimot {
namespace target {

// ---------------------------------------------------------------------------
// Continuous model (reference for the derivation and the tests)

/// Time derivative of the target pose.
struct TargetPoseRate {
  Eigen::Matrix3d R_dot;  // d/dt R_RtoT
  Eigen::Vector3d p_dot;  // d/dt p_TinR
};

/// Eq. 3: Ṙ_GtoT = −[w×] R_GtoT, ṗ_TinG = R_GtoTᵀ v.
TargetPoseRate global_dynamics(const TargetValue& x_global);

/// Eq. 5 with the IMU's true rate w_I (in I), its R_GtoI and v_IinG.
TargetPoseRate local_dynamics(const TargetValue& x_local, const Eigen::Matrix3d& R_GtoI,
                              const Eigen::Vector3d& v_IinG, const Eigen::Vector3d& w_I);

/// Linearised continuous error dynamics (paper Sec. III-A-1):
///   δẋ_T = A_T δx_T + A_x δx_I + Γ_T [n_v; n_w] + Γ_g n_g
/// (A_x, Γ_g zero for the global representation). Local:
///   δθ̇_T = −[ŵ×] δθ_T + δw_T + R̂_ItoT δb_g + R̂_ItoT n_g
///   δṗ_T = −[ω̂_I×] δp_T − R̂_ItoTᵀ [v̂×] δθ_T + R̂_ItoTᵀ δv_T
///          − [(R̂_GtoI v̂_IinG)×] δθ_I − R̂_GtoI δv_I − [p̂_TinI×] δb_g − [p̂_TinI×] n_g
/// Global: δθ̇_T = −[ŵ×] δθ_T + δw_T,  δṗ_T = −R̂_GtoTᵀ [v̂×] δθ_T + R̂_GtoTᵀ δv_T.
struct ContinuousLinearization {
  Matrix12d A_T{Matrix12d::Zero()};
  Matrix12x15d A_x{Matrix12x15d::Zero()};            // w.r.t. [δθ δp δv δbg δba] of the IMU
  Eigen::Matrix<double, 12, 6> Gamma_T{Eigen::Matrix<double, 12, 6>::Zero()};  // [n_v; n_w]
  Eigen::Matrix<double, 12, 3> Gamma_g{Eigen::Matrix<double, 12, 3>::Zero()};  // gyro noise n_g
};
ContinuousLinearization linearize_global(const TargetValue& x_global);
/// w_I_hat = ω_m − b̂_g (the bias-corrected gyro reading).
ContinuousLinearization linearize_local(const TargetValue& x_local, const estimator::ImuValue& imu,
                                        const Eigen::Vector3d& w_I_hat);

// ---------------------------------------------------------------------------
// Discrete propagation

/// Γ1(w, dt) = ∫₀^dt Exp(wτ) dτ (closed form, the estimator's).
Eigen::Matrix3d gamma1(const Eigen::Vector3d& w, double dt);

/// D1(w, v, dt) = ∂(Γ1(w, dt) v)/∂w = −∫₀^dt Exp(wτ) [v×] Jr(wτ) τ dτ
/// (composite 4-point Gauss–Legendre, sub-intervals with |w|h ≤ 0.25).
Eigen::Matrix3d d1_integral(const Eigen::Vector3d& w, const Eigen::Vector3d& v, double dt);

/// One global step of length dt >= 0 (see the header note): exact mean,
/// exact Jacobian Φ (12×12), and Q_G by quadrature. Phi/Q may be nullptr.
/// Throws std::invalid_argument for dt < 0 or invalid noise.
void propagate_global(const TargetValue& x, double dt, const TargetNoise& noise, TargetValue* x_new,
                      Matrix12d* Phi, Matrix12d* Q);

/// Result of one joint step with the IMU.
struct TargetStep {
  TargetValue x;                                 // target at t_k+1 (same representation)
  Matrix12d Phi_TT{Matrix12d::Identity()};       // ∂δx_T,k+1/∂δx_T,k
  Matrix12x15d Phi_TI{Matrix12x15d::Zero()};     // ∂δx_T,k+1/∂δx_I,k (zero for global)
  Matrix12d Q_TT{Matrix12d::Zero()};             // cov of the target's process noise at t_k+1
  Matrix12x15d Q_TI{Matrix12x15d::Zero()};       // cov(target noise, IMU noise w_I) (zero for global)
};

/// Target step over [t_k, t_k+1] (dt = t_k+1 − t_k) alongside the IMU step
/// imu_k → imu_k1 with its transition Phi_II and noise Q_II (15×15, error
/// order [δθ δp δv δbg δba]): a single Propagator::predict_step or a whole
/// Propagator::predict_interval. Only the poses of imu_k, imu_k1 and the
/// pose rows of Phi_II, Q_II are used (local); the global step ignores them.
/// Linearised at the given (current) estimates.
TargetStep propagate_target(TargetRepresentation representation, const TargetValue& x,
                            const estimator::ImuValue& imu_k, const estimator::ImuValue& imu_k1,
                            const Matrix15d& Phi_II, const Matrix15d& Q_II, double dt, const TargetNoise& noise);

/// Convenience: one IMU step with the estimator's Propagator::predict_step
/// (readings w_m, a_m held over dt; imu_lin the IMU linearisation point, e.g.
/// FEJ) followed by propagate_target. Outputs the IMU at t_k+1, Φ_II and Q_II.
TargetStep propagate_target_imu_step(TargetRepresentation representation, const TargetValue& x,
                                     const estimator::ImuValue& imu_k, const estimator::ImuValue& imu_lin,
                                     const Eigen::Vector3d& w_m, const Eigen::Vector3d& a_m, double dt,
                                     const Eigen::Vector3d& gravity, const estimator::ImuNoise& imu_noise,
                                     const TargetNoise& noise, estimator::ImuValue* imu_k1, Matrix15d* Phi_II,
                                     Matrix15d* Q_II);

/// Joint transition of [δx_I (15); δx_T (12)]:
///   Φ = [[Φ_II, 0], [Φ_TI, Φ_TT]],  Q = [[Q_II, Q_TIᵀ], [Q_TI, Q_TT]]
/// (for StateHelper::propagate with order {imu, target}).
void joint_transition(const Matrix15d& Phi_II, const Matrix15d& Q_II, const TargetStep& step,
                      Eigen::Matrix<double, 27, 27>* Phi, Eigen::Matrix<double, 27, 27>* Q);

/// Unobservable directions of the joint [δx_I (15); δx_T (12)] at (imu, x)
/// (docs/target_model.md, "Observability constraint"), 27×10:
///   0–2  the target gauge, T rotated on its body by α (in T):
///        target rows [α; 0; [v×]α; [w×]α] (its points −t + [p_FinT×]α with
///        t = 0, its clones the pose rows);
///   3–5  the target gauge, T's origin moved on its body by t (in T):
///        target rows [0; R_RtoTᵀ t; [w×]t; 0] (points −t);
///   6    the world yaw: IMU rows [R_GtoI e_z; −[p_IinG×]e_z; −[v_IinG×]e_z; 0; 0]
///        (the estimator's FEJ nullspace, propagator.h), global target rows
///        [R_GtoT e_z; −[p_TinG×]e_z; 0; 0], local target rows 0;
///   7–9  the world position: IMU rows [0; I; 0; 0; 0], global target [0; I; 0; 0],
///        local target 0.
/// The IMU rows of columns 0–5 are zero: the target gauge does not move the robot.
using JointNullspace = Eigen::Matrix<double, 27, 10>;
JointNullspace joint_unobservable_directions(TargetRepresentation representation, const estimator::ImuValue& imu,
                                             const TargetValue& x);

/// The columns of joint_unobservable_directions that stay unobservable under
/// the target's process noise. A gauge changes v, w with the state ([v×]α,
/// [w×]α, [w×]t), so along a run it needs the noise increments changed too;
/// it is exact only if that change is an isometry of the noise (the
/// likelihood is unchanged). Planar (v_x, v_y, w_z driven, isotropic in the
/// plane): the yaw (2) and the shift along z (5) — a roll or pitch moves
/// Δv_y, Δv_x into the undriven v_z (observable), an in-plane shift adds
/// [Δw×]t to Δv (a shear: weakly observable). Not planar: the three
/// rotations (0–2). Always the world's (6–9).
std::vector<int> noise_invariant_directions(bool planar);

/// Observability constraint (OC-EKF, Huang, Mourikis, Roumeliotis): the
/// smallest (Frobenius) change of the target rows [Φ_TI Φ_TT] of the joint
/// transition that maps the given columns of U, the unobservable directions
/// at t_k's linearisation point, exactly onto those of W, at t_k+1's:
///   [Φ_TI Φ_TT] ← [Φ_TI Φ_TT] − ([Φ_TI Φ_TT] U_c − W_c,T) U_c⁺   (W_c,T: target rows).
/// The IMU rows are the estimator's (its FEJ already maps them). The filter
/// passes noise_invariant_directions: constraining an observable direction
/// (e.g. the planar target's roll) makes the filter over-confident along it.
void constrain_observability(const JointNullspace& U, const JointNullspace& W, const std::vector<int>& columns,
                             TargetStep* step);

// ---------------------------------------------------------------------------
// Prediction of the target alone (no measurements)

struct TargetPrediction {
  TargetValue x;                          // global target at t + horizon
  Matrix12d P{Matrix12d::Zero()};         // its covariance
};

/// Global target to t + horizon_s (>= 0) with its own model:
///   x ← f_G(x, horizon),  P ← Φ_G P Φ_Gᵀ + Q_G   (mean exact; one step is
/// exact for any horizon up to the quadrature of Q_G, which subdivides).
TargetPrediction predict_global(const TargetValue& x_global, const Matrix12d& P_global, double horizon_s,
                                const TargetNoise& noise);

/// Local target to t + horizon_s: converted to global first with the IMU
/// pose at t (covariance from the joint [δθ_I, δp_I, δx_L] block, 18×18),
/// then predict_global. The IMU's own future motion is not modelled, so the
/// result is in G; global_to_local with a (predicted) IMU pose gives it back
/// in a local frame.
TargetPrediction predict_local_in_global(const PoseValue& imu_pose, const TargetValue& x_local,
                                         const Eigen::Matrix<double, 18, 18>& P_pose_target, double horizon_s,
                                         const TargetNoise& noise);

}  // namespace target
}  // namespace vimot

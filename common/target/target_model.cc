#include "common/target/target_model.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/math/quat.h"
#include "common/target/target_conversion.h"

namespace vimot {
namespace target {

namespace {

// 4-point Gauss–Legendre on [-1, 1].
constexpr double kGlNodes[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
constexpr double kGlWeights[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};

// Sub-intervals so that each one rotates by at most 0.25 rad. Bounded: a
// longer step (a future timestamp, an absurd rate) is an error, never a
// loop the caller cannot afford (1000 sub-intervals ≈ 40 turns, < 1 ms).
constexpr int kMaxSubintervals = 1000;
int num_subintervals(const Eigen::Vector3d& w, double dt) {
  const double n = std::ceil(w.norm() * dt / 0.25);
  if (!(n <= kMaxSubintervals)) {
    std::ostringstream msg;
    msg << "target propagation: rotation |w| dt = " << w.norm() * dt << " rad over " << dt
        << " s is beyond a meaningful prediction (limit " << 0.25 * kMaxSubintervals << " rad)";
    throw std::invalid_argument(msg.str());
  }
  return std::max(1, static_cast<int>(n));
}

void check_inputs(double dt, const TargetNoise& noise) {
  if (!(dt >= 0.0) || !std::isfinite(dt)) {
    std::ostringstream msg;
    msg << "target propagation: dt must be finite and >= 0, got " << dt;
    throw std::invalid_argument(msg.str());
  }
  if (!noise.valid()) throw std::invalid_argument("target propagation: noise densities must be finite and >= 0");
}

}  // namespace

// ---------------------------------------------------------------------------
// Continuous model

TargetPoseRate global_dynamics(const TargetValue& x) {
  const Eigen::Matrix3d R = x.R_RtoT();
  return TargetPoseRate{-skew(x.w_TinT) * R, R.transpose() * x.v_TinT};
}

TargetPoseRate local_dynamics(const TargetValue& x, const Eigen::Matrix3d& R_GtoI, const Eigen::Vector3d& v_IinG,
                              const Eigen::Vector3d& w_I) {
  const Eigen::Matrix3d R = x.R_RtoT();
  TargetPoseRate r;
  r.R_dot = -skew(x.w_TinT) * R + R * skew(w_I);
  r.p_dot = -skew(w_I) * x.p_TinR + R.transpose() * x.v_TinT - R_GtoI * v_IinG;
  return r;
}

ContinuousLinearization linearize_global(const TargetValue& x) {
  const Eigen::Matrix3d R = x.R_RtoT();
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  ContinuousLinearization c;
  c.A_T.block<3, 3>(0, 0) = -skew(x.w_TinT);
  c.A_T.block<3, 3>(0, 9) = I3;
  c.A_T.block<3, 3>(3, 0) = -R.transpose() * skew(x.v_TinT);
  c.A_T.block<3, 3>(3, 6) = R.transpose();
  c.Gamma_T.block<3, 3>(6, 0) = I3;
  c.Gamma_T.block<3, 3>(9, 3) = I3;
  return c;
}

ContinuousLinearization linearize_local(const TargetValue& x, const estimator::ImuValue& imu,
                                        const Eigen::Vector3d& w_I_hat) {
  const Eigen::Matrix3d R = x.R_RtoT();  // R_ItoT
  const Eigen::Matrix3d R_GtoI = quat_to_rot(imu.q_GtoI);
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  ContinuousLinearization c;
  c.A_T.block<3, 3>(0, 0) = -skew(x.w_TinT);
  c.A_T.block<3, 3>(0, 9) = I3;
  c.A_T.block<3, 3>(3, 0) = -R.transpose() * skew(x.v_TinT);
  c.A_T.block<3, 3>(3, 3) = -skew(w_I_hat);
  c.A_T.block<3, 3>(3, 6) = R.transpose();
  c.A_x.block<3, 3>(0, 9) = R;
  c.A_x.block<3, 3>(3, 0) = -skew(R_GtoI * imu.v_IinG);
  c.A_x.block<3, 3>(3, 6) = -R_GtoI;
  c.A_x.block<3, 3>(3, 9) = -skew(x.p_TinR);
  c.Gamma_T.block<3, 3>(6, 0) = I3;
  c.Gamma_T.block<3, 3>(9, 3) = I3;
  c.Gamma_g.block<3, 3>(0, 0) = R;
  c.Gamma_g.block<3, 3>(3, 0) = -skew(x.p_TinR);
  return c;
}

// ---------------------------------------------------------------------------
// Discrete propagation

Eigen::Matrix3d gamma1(const Eigen::Vector3d& w, double dt) {
  Eigen::Matrix3d G1, G2;
  estimator::Propagator::gamma_integrals(w, dt, &G1, &G2);
  return G1;
}

Eigen::Matrix3d d1_integral(const Eigen::Vector3d& w, const Eigen::Vector3d& v, double dt) {
  Eigen::Matrix3d D1 = Eigen::Matrix3d::Zero();
  if (dt <= 0.0) return D1;
  const Eigen::Matrix3d v_x = skew(v);
  const int n = num_subintervals(w, dt);
  const double h = dt / n;
  for (int s = 0; s < n; ++s) {
    for (int i = 0; i < 4; ++i) {
      const double tau = h * s + 0.5 * h * (kGlNodes[i] + 1.0);
      const Eigen::Vector3d wt = w * tau;
      D1 -= (0.5 * h * kGlWeights[i] * tau) * (exp_so3(wt) * v_x * jr_so3(wt));
    }
  }
  return D1;
}

void propagate_global(const TargetValue& x, double dt, const TargetNoise& noise, TargetValue* x_new,
                      Matrix12d* Phi, Matrix12d* Q) {
  check_inputs(dt, noise);
  const Eigen::Vector3d& w = x.w_TinT;
  const Eigen::Vector3d& v = x.v_TinT;
  const Eigen::Matrix3d R_k = x.R_RtoT();
  const Eigen::Matrix3d G1 = gamma1(w, dt);
  const Eigen::Vector3d dp_T = G1 * v;  // displacement, in T at t_k

  TargetValue xn = x;
  xn.q_RtoT = quat_multiply(rot_to_quat(exp_so3(-w * dt)), x.q_RtoT);
  xn.p_TinR = x.p_TinR + R_k.transpose() * dp_T;
  if (x_new) *x_new = xn;

  if (Phi) {
    Matrix12d F = Matrix12d::Identity();
    F.block<3, 3>(0, 0) = exp_so3(-w * dt);
    F.block<3, 3>(0, 9) = jr_so3(w * dt) * dt;
    F.block<3, 3>(3, 0) = -R_k.transpose() * skew(dp_T);
    F.block<3, 3>(3, 6) = R_k.transpose() * G1;
    F.block<3, 3>(3, 9) = R_k.transpose() * d1_integral(w, v, dt);
    *Phi = F;
  }

  if (Q) {
    // Q_G = ∫₀^dt M(τ) Q_c M(τ)ᵀ dτ; M(τ) = columns [v, w] of the step
    // Jacobian over the remaining s = dt − τ, at the state at τ:
    //   M = [[0, Jr(w s) s], [R_τᵀ Γ1(w, s), R_τᵀ D1(w, v, s)], [I, 0], [0, I]],
    //   R_τᵀ = R_kᵀ Exp(w τ).
    const Matrix6d Qc = noise.Qc();
    Matrix12d Qd = Matrix12d::Zero();
    if (dt > 0.0 && Qc.diagonal().maxCoeff() > 0.0) {
      const int n = num_subintervals(w, dt);
      const double h = dt / n;
      Eigen::Matrix<double, 12, 6> M = Eigen::Matrix<double, 12, 6>::Zero();
      M.block<3, 3>(6, 0).setIdentity();
      M.block<3, 3>(9, 3).setIdentity();
      for (int sub = 0; sub < n; ++sub) {
        for (int i = 0; i < 4; ++i) {
          const double tau = h * sub + 0.5 * h * (kGlNodes[i] + 1.0);
          const double s = dt - tau;
          const Eigen::Matrix3d R_tau_T = R_k.transpose() * exp_so3(w * tau);
          M.block<3, 3>(0, 3) = jr_so3(w * s) * s;
          M.block<3, 3>(3, 0) = R_tau_T * gamma1(w, s);
          M.block<3, 3>(3, 3) = R_tau_T * d1_integral(w, v, s);
          Qd += (0.5 * h * kGlWeights[i]) * (M * Qc * M.transpose());
        }
      }
    }
    *Q = 0.5 * (Qd + Qd.transpose());
  }
}

TargetStep propagate_target(TargetRepresentation representation, const TargetValue& x,
                            const estimator::ImuValue& imu_k, const estimator::ImuValue& imu_k1,
                            const Matrix15d& Phi_II, const Matrix15d& Q_II, double dt, const TargetNoise& noise) {
  TargetStep out;
  if (representation == TargetRepresentation::kGlobal) {
    propagate_global(x, dt, noise, &out.x, &out.Phi_TT, &out.Q_TT);
    return out;
  }
  // Local: x_L,k+1 = to_local(pose_k+1, f_G(to_global(pose_k, x_L,k))).
  const PoseValue pose_k = imu_pose(imu_k);
  const PoseValue pose_k1 = imu_pose(imu_k1);
  Matrix12x6d A_I, C;
  Matrix12d A_L, B, Phi_G, Q_G;
  const TargetValue x_G = local_to_global(pose_k, x, &A_I, &A_L);
  TargetValue x_G1;
  propagate_global(x_G, dt, noise, &x_G1, &Phi_G, &Q_G);
  out.x = global_to_local(pose_k1, x_G1, &C, &B);

  const Matrix12d BPhi = B * Phi_G;
  out.Phi_TT = BPhi * A_L;
  out.Phi_TI = C * Phi_II.topRows<6>();
  out.Phi_TI.leftCols<6>() += BPhi * A_I;
  const Matrix12d Q_TT = B * Q_G * B.transpose() + C * Q_II.topLeftCorner<6, 6>() * C.transpose();
  out.Q_TT = 0.5 * (Q_TT + Q_TT.transpose());
  out.Q_TI = C * Q_II.topRows<6>();
  return out;
}

TargetStep propagate_target_imu_step(TargetRepresentation representation, const TargetValue& x,
                                     const estimator::ImuValue& imu_k, const estimator::ImuValue& imu_lin,
                                     const Eigen::Vector3d& w_m, const Eigen::Vector3d& a_m, double dt,
                                     const Eigen::Vector3d& gravity, const estimator::ImuNoise& imu_noise,
                                     const TargetNoise& noise, estimator::ImuValue* imu_k1, Matrix15d* Phi_II,
                                     Matrix15d* Q_II) {
  estimator::ImuValue x1;
  Matrix15d F, Qd;
  estimator::Propagator::predict_step(imu_k, imu_lin, w_m, a_m, dt, gravity, imu_noise, &x1, &F, &Qd);
  if (imu_k1) *imu_k1 = x1;
  if (Phi_II) *Phi_II = F;
  if (Q_II) *Q_II = Qd;
  return propagate_target(representation, x, imu_k, x1, F, Qd, dt, noise);
}

void joint_transition(const Matrix15d& Phi_II, const Matrix15d& Q_II, const TargetStep& step,
                      Eigen::Matrix<double, 27, 27>* Phi, Eigen::Matrix<double, 27, 27>* Q) {
  if (Phi) {
    Phi->setZero();
    Phi->topLeftCorner<15, 15>() = Phi_II;
    Phi->block<12, 15>(15, 0) = step.Phi_TI;
    Phi->block<12, 12>(15, 15) = step.Phi_TT;
  }
  if (Q) {
    Q->topLeftCorner<15, 15>() = Q_II;
    Q->block<12, 15>(15, 0) = step.Q_TI;
    Q->block<15, 12>(0, 15) = step.Q_TI.transpose();
    Q->block<12, 12>(15, 15) = step.Q_TT;
  }
}

JointNullspace joint_unobservable_directions(TargetRepresentation representation, const estimator::ImuValue& imu,
                                             const TargetValue& x) {
  JointNullspace N = JointNullspace::Zero();
  const Eigen::Matrix3d R_RtoT = quat_to_rot(x.q_RtoT);
  const Eigen::Vector3d e_z = Eigen::Vector3d::UnitZ();
  // Target gauge (target rows start at 15).
  N.block<3, 3>(15, 0) = Eigen::Matrix3d::Identity();
  N.block<3, 3>(21, 0) = skew(x.v_TinT);
  N.block<3, 3>(24, 0) = skew(x.w_TinT);
  N.block<3, 3>(18, 3) = R_RtoT.transpose();
  N.block<3, 3>(21, 3) = skew(x.w_TinT);
  // World yaw and position.
  N.block<3, 1>(0, 6) = quat_to_rot(imu.q_GtoI) * e_z;
  N.block<3, 1>(3, 6) = -skew(imu.p_IinG) * e_z;
  N.block<3, 1>(6, 6) = -skew(imu.v_IinG) * e_z;
  N.block<3, 3>(3, 7) = Eigen::Matrix3d::Identity();
  if (representation == TargetRepresentation::kGlobal) {
    N.block<3, 1>(15, 6) = R_RtoT * e_z;
    N.block<3, 1>(18, 6) = -skew(x.p_TinR) * e_z;
    N.block<3, 3>(18, 7) = Eigen::Matrix3d::Identity();
  }
  return N;
}

std::vector<int> noise_invariant_directions(bool planar) {
  return planar ? std::vector<int>{2, 5, 6, 7, 8, 9} : std::vector<int>{0, 1, 2, 6, 7, 8, 9};
}

void constrain_observability(const JointNullspace& U, const JointNullspace& W, const std::vector<int>& columns,
                             TargetStep* step) {
  const Eigen::Index n = static_cast<Eigen::Index>(columns.size());
  Eigen::Matrix<double, 27, Eigen::Dynamic> U_c(27, n), W_c(27, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const int c = columns[static_cast<size_t>(i)];
    if (c < 0 || c >= U.cols()) throw std::invalid_argument("constrain_observability: no column " + std::to_string(c));
    U_c.col(i) = U.col(c);
    W_c.col(i) = W.col(c);
  }
  Eigen::Matrix<double, 12, 27> Phi_T;
  Phi_T << step->Phi_TI, step->Phi_TT;
  // U's columns are independent (its IMU rows separate the world columns from
  // the target ones), so U_c⁺ = (U_cᵀU_c)⁻¹U_cᵀ.
  const Eigen::MatrixXd U_pinv = (U_c.transpose() * U_c).ldlt().solve(U_c.transpose());
  Phi_T -= (Phi_T * U_c - W_c.bottomRows<12>()) * U_pinv;
  step->Phi_TI = Phi_T.leftCols<15>();
  step->Phi_TT = Phi_T.rightCols<12>();
}

// ---------------------------------------------------------------------------
// Prediction

TargetPrediction predict_global(const TargetValue& x_global, const Matrix12d& P_global, double horizon_s,
                                const TargetNoise& noise) {
  TargetPrediction out;
  Matrix12d Phi, Q;
  propagate_global(x_global, horizon_s, noise, &out.x, &Phi, &Q);
  const Matrix12d P = Phi * P_global * Phi.transpose() + Q;
  out.P = 0.5 * (P + P.transpose());
  return out;
}

TargetPrediction predict_local_in_global(const PoseValue& imu_pose, const TargetValue& x_local,
                                         const Eigen::Matrix<double, 18, 18>& P_pose_target, double horizon_s,
                                         const TargetNoise& noise) {
  const TargetValue x_G = local_to_global(imu_pose, x_local);
  const Matrix12d P_G = local_to_global_covariance(imu_pose, x_local, P_pose_target);
  return predict_global(x_G, P_G, horizon_s, noise);
}

}  // namespace target
}  // namespace vimot

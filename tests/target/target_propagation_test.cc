#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <cmath>

#include "common/estimator/propagator.h"
#include "common/math/quat.h"
#include "common/target/target_conversion.h"
#include "common/target/target_filter.h"
#include "common/target/target_measurement.h"
#include "common/target/target_model.h"
#include "target_test_util.h"

using namespace vimot;
using namespace vimot::target;
using vimot::estimator::ImuNoise;
using vimot::estimator::ImuValue;
using vimot::target::test::central_diff;
using vimot::target::test::rel_err;

namespace {

const Eigen::Vector3d kGravity(0.0, 0.0, 9.81);

TargetNoise sample_noise() {
  TargetNoise n;
  n.sigma_v = Eigen::Vector3d(0.3, 0.2, 0.1);
  n.sigma_w = Eigen::Vector3d(0.05, 0.1, 0.2);
  return n;
}

std::vector<int> all_columns() { return {0, 1, 2, 3, 4, 5, 6, 7, 8, 9}; }

double min_eig(const Eigen::MatrixXd& M) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M).eigenvalues().minCoeff();
}

// ∫₀^t Exp(wτ) dτ by Rodrigues, written independently of the library.
Eigen::Matrix3d integral_exp(const Eigen::Vector3d& w, double t) {
  const double th = w.norm();
  if (th < 1e-12) return t * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d K = skew(w / th);
  return t * Eigen::Matrix3d::Identity() + (1.0 - std::cos(th * t)) / th * K + (t - std::sin(th * t) / th) * K * K;
}

// Closed-form global truth for constant v, w: R(t) = exp(−w t) R0, p(t) = p0 + R0ᵀ ∫Exp(wτ)dτ v.
TargetValue global_truth(const TargetValue& x0, double t) {
  TargetValue x = x0;
  x.q_RtoT = rot_to_quat(exp_so3(-x0.w_TinT * t) * x0.R_RtoT());
  x.p_TinR = x0.p_TinR + x0.R_RtoT().transpose() * integral_exp(x0.w_TinT, t) * x0.v_TinT;
  return x;
}

// A smooth IMU trajectory (pose only matters for the target): wobbling rotation and a helix.
ImuValue imu_at(double t) {
  ImuValue x;
  const Eigen::Vector3d rv(0.3 * std::sin(0.7 * t), 0.2 * std::cos(0.5 * t), 0.4 * t);
  x.q_GtoI = rot_to_quat(exp_so3(rv));
  x.p_IinG = Eigen::Vector3d(3.0 * std::cos(0.5 * t), 2.0 * std::sin(0.5 * t), 0.3 * t);
  x.v_IinG = Eigen::Vector3d(-1.5 * std::sin(0.5 * t), 1.0 * std::cos(0.5 * t), 0.3);
  return x;
}

// Local target from IMU and global target, written independently of the library.
TargetValue to_local_truth(const ImuValue& imu, const TargetValue& g) {
  const Eigen::Matrix3d R_GtoI = quat_to_rot(imu.q_GtoI);
  TargetValue l = g;
  l.q_RtoT = rot_to_quat(g.R_RtoT() * R_GtoI.transpose());
  l.p_TinR = R_GtoI * (g.p_TinR - imu.p_IinG);
  return l;
}

}  // namespace

TEST_CASE("gamma1 and D1 match numerical integration / differentiation", "[target]") {
  const Eigen::Vector3d v(0.7, -0.3, 1.1);
  for (double scale : {0.0, 1e-4, 0.5, 12.0}) {
    const Eigen::Vector3d w = scale * Eigen::Vector3d(0.3, -0.5, 0.8);
    const double dt = 0.4;
    Eigen::Matrix3d N1 = Eigen::Matrix3d::Zero();
    const int n = 20000;
    for (int i = 0; i < n; ++i) N1 += exp_so3(w * ((i + 0.5) * dt / n)) * dt / n;
    CHECK(rel_err(gamma1(w, dt), N1) < 1e-7);
    const Eigen::MatrixXd ND = central_diff(3, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return gamma1(w + Eigen::Vector3d(d), dt) * v;
    });
    INFO("scale " << scale);
    CHECK(rel_err(d1_integral(w, v, dt), ND) < 1e-8);
  }
}

TEST_CASE("global step: Phi equals central finite differences", "[target]") {
  for (double scale : {0.0, 1.0, 15.0}) {
    for (double dt : {0.005, 0.5}) {
      const TargetValue x = test::sample_target(scale);
      TargetValue x1;
      Matrix12d Phi, Q;
      propagate_global(x, dt, sample_noise(), &x1, &Phi, &Q);
      const Eigen::MatrixXd N = central_diff(12, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        TargetValue y;
        propagate_global(boxplus(x, Vector12d(d)), dt, sample_noise(), &y, nullptr, nullptr);
        return boxminus(y, x1);
      });
      INFO("scale " << scale << " dt " << dt);
      CHECK(rel_err(Phi, N) < 1e-7);
    }
  }
}

TEST_CASE("local step: Phi_TT and Phi_TI equal central finite differences", "[target]") {
  const ImuValue imu = test::sample_imu();
  const TargetValue x = test::sample_target();
  const TargetNoise tn = sample_noise();
  for (double rate : {0.0, 1.0, 8.0}) {
    const Eigen::Vector3d w_m = imu.bg + rate * Eigen::Vector3d(0.4, -0.7, 1.1);
    const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
    for (double dt : {0.005, 0.1}) {
      ImuValue imu1;
      Matrix15d Phi_II, Q_II;
      const TargetStep s = propagate_target_imu_step(TargetRepresentation::kLocal, x, imu, imu, w_m, a_m, dt,
                                                     kGravity, ImuNoise{}, tn, &imu1, &Phi_II, &Q_II);
      auto step = [&](const ImuValue& i0, const TargetValue& t0) {
        return propagate_target_imu_step(TargetRepresentation::kLocal, t0, i0, i0, w_m, a_m, dt, kGravity,
                                         ImuNoise{}, tn, nullptr, nullptr, nullptr)
            .x;
      };
      const Eigen::MatrixXd NT = central_diff(12, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        return boxminus(step(imu, boxplus(x, Vector12d(d))), s.x);
      });
      const Eigen::MatrixXd NI = central_diff(15, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        return boxminus(step(estimator::boxplus(imu, Eigen::Matrix<double, 15, 1>(d)), x), s.x);
      });
      INFO("rate " << rate << " dt " << dt);
      CHECK(rel_err(s.Phi_TT, NT) < 1e-7);
      CHECK(rel_err(s.Phi_TI, NI) < 1e-7);
      // The global step never couples to the IMU.
      const TargetStep g = propagate_target(TargetRepresentation::kGlobal, x, imu, imu1, Phi_II, Q_II, dt, tn);
      CHECK(g.Phi_TI.isZero(0.0));
      CHECK(g.Q_TI.isZero(0.0));
    }
  }
}

TEST_CASE("continuous dynamics (Eq. 3, 5) equal the derivative of the composed truth", "[target]") {
  const TargetValue xg0 = test::sample_target();
  const Eigen::Vector3d w_I(0.3, -0.6, 0.9);  // IMU true rate, constant
  const ImuValue imu0 = test::sample_imu();
  auto imu_t = [&](double t) {  // constant rate and velocity
    ImuValue x = imu0;
    x.q_GtoI = rot_to_quat(exp_so3(-w_I * t) * quat_to_rot(imu0.q_GtoI));
    x.p_IinG = imu0.p_IinG + imu0.v_IinG * t;
    return x;
  };
  const double h = 1e-5;
  // Global.
  const TargetPoseRate rg = global_dynamics(xg0);
  const TargetValue gp = global_truth(xg0, h), gm = global_truth(xg0, -h);
  CHECK(rel_err(rg.R_dot, (gp.R_RtoT() - gm.R_RtoT()) / (2 * h)) < 1e-8);
  CHECK(rel_err(rg.p_dot, (gp.p_TinR - gm.p_TinR) / (2 * h)) < 1e-8);
  // Local.
  const TargetValue xl0 = to_local_truth(imu0, xg0);
  const TargetValue lp = to_local_truth(imu_t(h), gp), lm = to_local_truth(imu_t(-h), gm);
  const TargetPoseRate rl = local_dynamics(xl0, quat_to_rot(imu0.q_GtoI), imu0.v_IinG, w_I);
  CHECK(rel_err(rl.R_dot, (lp.R_RtoT() - lm.R_RtoT()) / (2 * h)) < 1e-8);
  CHECK(rel_err(rl.p_dot, (lp.p_TinR - lm.p_TinR) / (2 * h)) < 1e-8);
}

TEST_CASE("discrete step tends to the continuous linearisation (A_T, A_x, Gamma) as dt -> 0", "[target]") {
  const ImuValue imu = test::sample_imu();
  const TargetValue x = test::sample_target();
  const TargetNoise tn = sample_noise();
  const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.4, -0.7, 1.1);
  const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
  ImuNoise in;
  in.sigma_w = 0.01;
  const double dt = 1e-5;
  for (TargetRepresentation rep : {TargetRepresentation::kGlobal, TargetRepresentation::kLocal}) {
    INFO(to_string(rep));
    const TargetStep s =
        propagate_target_imu_step(rep, x, imu, imu, w_m, a_m, dt, kGravity, in, tn, nullptr, nullptr, nullptr);
    const ContinuousLinearization c =
        rep == TargetRepresentation::kGlobal ? linearize_global(x) : linearize_local(x, imu, w_m - imu.bg);
    CHECK(rel_err((s.Phi_TT - Matrix12d::Identity()) / dt, c.A_T) < 1e-3);
    CHECK(rel_err(s.Phi_TI / dt, c.A_x) < 1e-3);
    const double sg2 = in.sigma_w * in.sigma_w;
    const Matrix12d Qc_T = c.Gamma_T * tn.Qc() * c.Gamma_T.transpose() + sg2 * c.Gamma_g * c.Gamma_g.transpose();
    CHECK(rel_err(s.Q_TT / dt, Qc_T) < 1e-3);
    // IMU: δθ̇_I = ... − n_g, so cov(target noise, IMU noise)/dt → [−σ_g² Γ_g, 0].
    Matrix12x15d Qc_TI = Matrix12x15d::Zero();
    Qc_TI.leftCols<3>() = -sg2 * c.Gamma_g;
    CHECK((s.Q_TI / dt - Qc_TI).cwiseAbs().maxCoeff() < 1e-3 * sg2 * 10.0);
  }
}

TEST_CASE("noise-free global propagation matches the closed-form constant-velocity truth", "[target]") {
  const TargetValue x0 = test::sample_target(2.0);
  const double dt = 0.005;
  const int n = 2000;  // 10 s, several full turns
  TargetValue x = x0;
  for (int k = 0; k < n; ++k) propagate_global(x, dt, sample_noise(), &x, nullptr, nullptr);
  const TargetValue truth = global_truth(x0, n * dt);
  CHECK(boxminus(x, truth).norm() < 1e-9);
}

TEST_CASE("noise-free local propagation follows the composed truth while the IMU moves", "[target]") {
  const TargetValue xg0 = test::sample_target(1.5);
  const double dt = 0.005;
  const int n = 2000;
  TargetValue xl = to_local_truth(imu_at(0.0), xg0);
  const Matrix15d I15 = Matrix15d::Identity(), Z15 = Matrix15d::Zero();
  for (int k = 0; k < n; ++k) {
    xl = propagate_target(TargetRepresentation::kLocal, xl, imu_at(k * dt), imu_at((k + 1) * dt), I15, Z15, dt,
                          sample_noise())
             .x;
  }
  const TargetValue truth = to_local_truth(imu_at(n * dt), global_truth(xg0, n * dt));
  CHECK(boxminus(xl, truth).norm() < 1e-9);
}

TEST_CASE("local and global propagations agree once converted (estimator IMU steps)", "[target]") {
  ImuValue imu = test::sample_imu();
  TargetValue xg = test::sample_target();
  TargetValue xl = global_to_local(imu_pose(imu), xg);
  const TargetNoise tn = sample_noise();
  const double dt = 0.005;
  for (int k = 0; k < 400; ++k) {
    const double t = k * dt;
    const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.5 * std::sin(t), -0.3, 0.8 * std::cos(2 * t));
    const Eigen::Vector3d a_m = Eigen::Vector3d(0.5 * std::cos(t), 0.2, 9.7);
    ImuValue imu1;
    Matrix15d Phi_II, Q_II;
    xl = propagate_target_imu_step(TargetRepresentation::kLocal, xl, imu, imu, w_m, a_m, dt, kGravity, ImuNoise{},
                                   tn, &imu1, &Phi_II, &Q_II)
             .x;
    xg = propagate_target(TargetRepresentation::kGlobal, xg, imu, imu1, Phi_II, Q_II, dt, tn).x;
    imu = imu1;
  }
  CHECK(boxminus(local_to_global(imu_pose(imu), xl), xg).norm() < 1e-10);
}

TEST_CASE("Q is symmetric PSD; planar noise leaves the undriven axes noise-free", "[target]") {
  const ImuValue imu = test::sample_imu();
  const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.4, -0.7, 1.1);
  const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
  for (TargetRepresentation rep : {TargetRepresentation::kGlobal, TargetRepresentation::kLocal}) {
    for (bool planar : {false, true}) {
      INFO(to_string(rep) << (planar ? " planar" : " full"));
      TargetValue x = test::sample_target();
      const TargetNoise tn = planar ? TargetNoise::planar(0.2, 0.1) : sample_noise();
      if (planar) {  // planar motion: yaw-only orientation, w along z, v in the plane
        x.q_RtoT = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, 0.8)));
        x.w_TinT = Eigen::Vector3d(0.0, 0.0, 0.6);
        x.v_TinT = Eigen::Vector3d(1.0, 0.2, 0.0);
      }
      Matrix15d Phi_II, Q_II;
      const TargetStep s = propagate_target_imu_step(rep, x, imu, imu, w_m, a_m, 0.05, kGravity, ImuNoise{}, tn,
                                                     nullptr, &Phi_II, &Q_II);
      CHECK((s.Q_TT - s.Q_TT.transpose()).norm() == 0.0);
      CHECK(min_eig(s.Q_TT) > -1e-18);
      Eigen::Matrix<double, 27, 27> Phi, Q;
      joint_transition(Phi_II, Q_II, s, &Phi, &Q);
      CHECK((Q - Q.transpose()).norm() < 1e-20);
      CHECK(min_eig(Q) > -1e-15);
      if (planar) {
        for (int i : {8, 9, 10}) {  // v_z, w_x, w_y
          CHECK(s.Q_TT.row(i).isZero(0.0));
          CHECK(s.Q_TT.col(i).isZero(0.0));
        }
        if (rep == TargetRepresentation::kGlobal) {
          for (int i : {0, 1, 5}) CHECK(s.Q_TT.row(i).cwiseAbs().maxCoeff() < 1e-18);  // θ_x, θ_y, p_z
        }
      } else {
        CHECK(min_eig(s.Q_TT.bottomRightCorner<6, 6>()) > 0.0);
      }
    }
  }
}

TEST_CASE("per-IMU-step chaining equals one call over the whole interval", "[target]") {
  // The local target depends on the IMU only through the interval's end poses,
  // so Φ_II, Q_II of predict_interval can be used for a whole camera interval.
  ImuValue imu = test::sample_imu();
  const ImuValue imu0 = imu;
  const TargetValue x0 = test::sample_target();
  const TargetNoise tn = sample_noise();
  ImuNoise in;
  in.sigma_w = 0.01;
  in.sigma_a = 0.05;
  for (TargetRepresentation rep : {TargetRepresentation::kGlobal, TargetRepresentation::kLocal}) {
    INFO(to_string(rep));
    imu = imu0;
    TargetValue x = x0;
    Eigen::Matrix<double, 27, 27> Phi_acc = Eigen::Matrix<double, 27, 27>::Identity();
    Eigen::Matrix<double, 27, 27> Q_acc = Eigen::Matrix<double, 27, 27>::Zero();
    Matrix15d Phi_II_acc = Matrix15d::Identity(), Q_II_acc = Matrix15d::Zero();
    const double dt = 0.005;
    const int n = 20;
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.6, -0.4 + 0.05 * k, 0.9);
      const Eigen::Vector3d a_m(0.3 * k, -0.2, 9.8);
      ImuValue imu1;
      Matrix15d Phi_II, Q_II;
      const TargetStep s =
          propagate_target_imu_step(rep, x, imu, imu, w_m, a_m, dt, kGravity, in, tn, &imu1, &Phi_II, &Q_II);
      Eigen::Matrix<double, 27, 27> Phi, Q;
      joint_transition(Phi_II, Q_II, s, &Phi, &Q);
      Phi_acc = Phi * Phi_acc;
      Q_acc = Phi * Q_acc * Phi.transpose() + Q;
      Phi_II_acc = Phi_II * Phi_II_acc;
      Q_II_acc = Phi_II * Q_II_acc * Phi_II.transpose() + Q_II;
      x = s.x;
      imu = imu1;
    }
    const TargetStep one = propagate_target(rep, x0, imu0, imu, Phi_II_acc, Q_II_acc, n * dt, tn);
    CHECK(boxminus(one.x, x).norm() < 1e-12);
    CHECK(rel_err(one.Phi_TT, Phi_acc.block<12, 12>(15, 15)) < 1e-10);
    CHECK(rel_err(one.Phi_TI, Phi_acc.block<12, 15>(15, 0)) < 1e-10);
    const double qs = Q_acc.block<12, 12>(15, 15).cwiseAbs().maxCoeff();
    CHECK((one.Q_TT - Q_acc.block<12, 12>(15, 15)).cwiseAbs().maxCoeff() < 1e-9 * qs);
    CHECK((one.Q_TI - Q_acc.block<12, 15>(15, 0)).cwiseAbs().maxCoeff() < 1e-9 * qs);
  }
}

TEST_CASE("prediction: one long step equals chained steps; local prediction goes through global", "[target]") {
  const TargetValue x = test::sample_target(3.0);
  const TargetNoise tn = sample_noise();
  Matrix12d P0 = Matrix12d::Identity() * 1e-3;
  P0(0, 4) = P0(4, 0) = 2e-4;
  const TargetPrediction one = predict_global(x, P0, 2.0, tn);
  TargetValue xc = x;
  Matrix12d Pc = P0;
  for (int k = 0; k < 40; ++k) {
    Matrix12d Phi, Q;
    propagate_global(xc, 0.05, tn, &xc, &Phi, &Q);
    Pc = Phi * Pc * Phi.transpose() + Q;
  }
  CHECK(boxminus(one.x, xc).norm() < 1e-10);
  CHECK(rel_err(one.P, Pc) < 1e-8);
  CHECK(min_eig(one.P) > 0.0);

  const PoseValue pose = imu_pose(test::sample_imu());
  Eigen::Matrix<double, 18, 18> Pj = Eigen::Matrix<double, 18, 18>::Identity() * 1e-3;
  const TargetValue xl = global_to_local(pose, x);
  const TargetPrediction pl = predict_local_in_global(pose, xl, Pj, 2.0, tn);
  const TargetPrediction pg = predict_global(x, local_to_global_covariance(pose, xl, Pj), 2.0, tn);
  CHECK(boxminus(pl.x, pg.x).norm() < 1e-10);
  CHECK(rel_err(pl.P, pg.P) < 1e-12);
  CHECK_THROWS_AS(predict_global(x, P0, -1.0, tn), std::invalid_argument);
}

// ---------------------------------------------------------------------------
// Unobservable directions and the observability constraint
namespace {

// The target gauge applied by definition: T' on the same body, rotated by
// R_TtoT' = Exp(−α) and with its origin at t (in T). Points p' = R_TtoT'(p − t).
TargetValue gauge_target(const TargetValue& x, const Eigen::Vector3d& alpha, const Eigen::Vector3d& t) {
  const Eigen::Matrix3d R_TtoTp = exp_so3(-alpha);
  TargetValue y = x;
  y.q_RtoT = rot_to_quat(R_TtoTp * x.R_RtoT());
  y.p_TinR = x.p_TinR + x.R_RtoT().transpose() * t;
  y.v_TinT = R_TtoTp * (x.v_TinT + x.w_TinT.cross(t));
  y.w_TinT = R_TtoTp * x.w_TinT;
  return y;
}

// The world moved: rotated by φ about z and shifted by d (G' ← G).
ImuValue gauge_world(const ImuValue& imu, double phi, const Eigen::Vector3d& d) {
  const Eigen::Matrix3d Rz = exp_so3(phi * Eigen::Vector3d::UnitZ());
  ImuValue y = imu;
  y.q_GtoI = rot_to_quat(quat_to_rot(imu.q_GtoI) * Rz.transpose());
  y.p_IinG = Rz * imu.p_IinG + d;
  y.v_IinG = Rz * imu.v_IinG;
  return y;
}
TargetValue gauge_world(const TargetValue& x, double phi, const Eigen::Vector3d& d) {
  const Eigen::Matrix3d Rz = exp_so3(phi * Eigen::Vector3d::UnitZ());
  TargetValue y = x;
  y.q_RtoT = rot_to_quat(x.R_RtoT() * Rz.transpose());
  y.p_TinR = Rz * x.p_TinR + d;
  return y;
}

}  // namespace

TEST_CASE("unobservable directions: the gauge transformations' derivatives, kept by the exact step, "
          "annihilated by the point Jacobians", "[target]") {
  const ImuValue imu = test::sample_imu();
  const TargetValue x = test::sample_target();
  for (TargetRepresentation rep : {TargetRepresentation::kLocal, TargetRepresentation::kGlobal}) {
    const bool global = rep == TargetRepresentation::kGlobal;
    INFO((global ? "global" : "local"));
    const JointNullspace N = joint_unobservable_directions(rep, imu, x);
    // Columns against finite differences of the transformations themselves.
    const Eigen::MatrixXd Ng = central_diff(6, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      Eigen::VectorXd e(27);
      e << Eigen::Matrix<double, 15, 1>::Zero(), boxminus(gauge_target(x, d.head<3>(), d.tail<3>()), x);
      return e;
    });
    const Eigen::MatrixXd Nw = central_diff(4, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      Eigen::VectorXd e(27);
      const TargetValue xw = global ? gauge_world(x, d(0), d.tail<3>()) : x;
      e << boxminus(gauge_world(imu, d(0), d.tail<3>()), imu), boxminus(xw, x);
      return e;
    });
    CHECK(rel_err(N.leftCols<6>(), Ng) < 1e-8);
    CHECK(rel_err(N.rightCols<4>(), Nw) < 1e-8);

    // The exact joint step (IMU linearised at its estimate) maps them onto themselves.
    const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.4, -0.7, 1.1);
    const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
    ImuValue imu1;
    Matrix15d Phi_II, Q_II;
    const TargetStep s = propagate_target_imu_step(rep, x, imu, imu, w_m, a_m, 0.1, kGravity, ImuNoise{},
                                                   sample_noise(), &imu1, &Phi_II, &Q_II);
    Eigen::Matrix<double, 27, 27> Phi, Q;
    joint_transition(Phi_II, Q_II, s, &Phi, &Q);
    const JointNullspace N1 = joint_unobservable_directions(rep, imu1, s.x);
    CHECK(rel_err(Phi * N, N1) < 1e-9);

    // A target point's measurement does not see them: target pose, point
    // (gauge rows [p_FinT×]α − t, world rows 0) and, global, the IMU pose.
    const Eigen::Vector3d p_FinT(0.3, -0.2, 0.4);
    CameraExtrinsics cam;
    cam.R_ItoC = exp_so3(Eigen::Vector3d(0.1, 1.4, -0.2));
    cam.p_IinC = Eigen::Vector3d(0.05, -0.02, 0.01);
    const TargetPointPrediction pred = predict_target_point(rep, PoseValue{imu.q_GtoI, imu.p_IinG},
                                                            PoseValue{x.q_RtoT, x.p_TinR}, p_FinT, cam, -1e9);
    Eigen::Matrix<double, 3, 10> N_point = Eigen::Matrix<double, 3, 10>::Zero();
    N_point.leftCols<3>() = skew(p_FinT);
    N_point.middleCols<3>(3) = -Eigen::Matrix3d::Identity();
    const Eigen::Matrix<double, 2, 10> HN =
        pred.H_imu_pose * N.topRows<6>() + pred.H_target_pose * N.middleRows<6>(15) + pred.H_point * N_point;
    CHECK(HN.cwiseAbs().maxCoeff() < 1e-12 * std::max(1.0, pred.H_target_pose.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("observability constraint: the first-estimate step maps the directions onto the next first "
          "estimate's, with a change of the size of the mismatch", "[target]") {
  const ImuValue imu = test::sample_imu();
  const TargetValue x = test::sample_target();
  // First estimates that differ from the (updated) estimates, as after an update.
  ImuValue imu_lin = imu;
  imu_lin.q_GtoI = quat_boxplus(imu.q_GtoI, Eigen::Vector3d(0.002, -0.001, 0.003));
  imu_lin.p_IinG += Eigen::Vector3d(0.01, 0.02, -0.01);
  imu_lin.v_IinG += Eigen::Vector3d(-0.005, 0.002, 0.004);
  Vector12d dx;
  dx << 0.003, -0.002, 0.001, 0.01, -0.02, 0.015, 0.05, -0.03, 0.02, 0.02, -0.01, 0.03;
  const TargetValue x_lin = boxplus(x, dx);
  const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.4, -0.7, 1.1);
  const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
  for (TargetRepresentation rep : {TargetRepresentation::kLocal, TargetRepresentation::kGlobal}) {
    INFO((rep == TargetRepresentation::kGlobal ? "global" : "local"));
    // The filter's step: mean from the estimates, Φ at the first estimates.
    ImuValue imu1;
    Matrix15d Phi_II, Q_II;
    const TargetStep mean = propagate_target_imu_step(rep, x, imu, imu_lin, w_m, a_m, 0.1, kGravity, ImuNoise{},
                                                      sample_noise(), &imu1, &Phi_II, &Q_II);
    TargetStep lin = propagate_target(rep, x_lin, imu_lin, imu1, Phi_II, Q_II, 0.1, sample_noise());
    const JointNullspace U = joint_unobservable_directions(rep, imu_lin, x_lin);
    const JointNullspace W = joint_unobservable_directions(rep, imu1, mean.x);
    Eigen::Matrix<double, 27, 27> Phi;
    joint_transition(Phi_II, Q_II, lin, &Phi, nullptr);
    const double before = (Phi * U - W).bottomRows<12>().cwiseAbs().maxCoeff();
    const TargetStep unconstrained = lin;
    constrain_observability(U, W, all_columns(), &lin);
    joint_transition(Phi_II, Q_II, lin, &Phi, nullptr);
    const double after = (Phi * U - W).bottomRows<12>().cwiseAbs().maxCoeff();
    Eigen::Matrix<double, 12, 27> change;
    change << lin.Phi_TI - unconstrained.Phi_TI, lin.Phi_TT - unconstrained.Phi_TT;
    INFO("mismatch before " << before << " after " << after << " largest change of Φ " << change.cwiseAbs().maxCoeff());
    CHECK(before > 1e-3);  // the unconstrained first-estimate step leaks
    CHECK(after < 1e-12);
    // The smallest change: its rows lie in the span of U's columns.
    const Eigen::Matrix<double, 27, 27> P_U = U * (U.transpose() * U).inverse() * U.transpose();
    CHECK((change - change * P_U).cwiseAbs().maxCoeff() < 1e-12);

    // Already consistent (first estimates = estimates): nothing changes.
    ImuValue imu1e;
    TargetStep exact = propagate_target_imu_step(rep, x, imu, imu, w_m, a_m, 0.1, kGravity, ImuNoise{},
                                                 sample_noise(), &imu1e, &Phi_II, &Q_II);
    const TargetStep exact0 = exact;
    constrain_observability(joint_unobservable_directions(rep, imu, x),
                            joint_unobservable_directions(rep, imu1e, exact.x), all_columns(), &exact);
    CHECK((exact.Phi_TT - exact0.Phi_TT).cwiseAbs().maxCoeff() < 1e-10);
    CHECK((exact.Phi_TI - exact0.Phi_TI).cwiseAbs().maxCoeff() < 1e-10);
  }
}

TEST_CASE("observability constraint: only the gauges the process noise keeps, and only those constrained",
          "[target]") {
  const ImuValue imu = test::sample_imu();
  const TargetValue x = test::sample_target();
  for (const bool planar : {true, false}) {
    INFO((planar ? "planar" : "all six rates driven"));
    TargetFilterOptions options;
    options.planar = planar;
    const TargetNoise noise = options.noise(0.3);
    Eigen::Matrix<double, 6, 1> var;
    var << noise.sigma_v.cwiseAbs2(), noise.sigma_w.cwiseAbs2();
    // A gauge column's v, w rows depend on v, w, so along a run it needs each
    // noise increment n = (Δv, Δw) changed by M n, M its derivative in (v, w)
    // (finite differences of the columns). The gauge stays exact only if that
    // is an isometry of the noise: M keeps the driven components among
    // themselves and Σ⁻¹M is skew on them.
    std::vector<int> invariant;
    for (int c = 0; c < 6; ++c) {
      const Eigen::MatrixXd M = central_diff(6, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
        TargetValue y = x;
        y.v_TinT += d.head<3>();
        y.w_TinT += d.tail<3>();
        return joint_unobservable_directions(TargetRepresentation::kLocal, imu, y).col(c).segment<6>(21);
      });
      double leak = 0.0, asym = 0.0;
      for (int i = 0; i < 6; ++i) {
        for (int j = 0; j < 6; ++j) {
          if (var(j) == 0.0) continue;
          if (var(i) == 0.0) {
            leak = std::max(leak, std::abs(M(i, j)));
          } else {
            asym = std::max(asym, std::abs(M(i, j) / var(i) + M(j, i) / var(j)));
          }
        }
      }
      INFO("column " << c << ": into undriven " << leak << ", not skew " << asym);
      if (leak < 1e-8 && asym < 1e-6) invariant.push_back(c);
    }
    for (const int c : {6, 7, 8, 9}) invariant.push_back(c);  // the world's: the target noise does not move them
    CHECK(invariant == noise_invariant_directions(planar));

    // The constraint with those columns maps them, and changes Φ only in their span.
    ImuValue imu_lin = imu;
    imu_lin.p_IinG += Eigen::Vector3d(0.01, 0.02, -0.01);
    Vector12d dx;
    dx << 0.003, -0.002, 0.001, 0.01, -0.02, 0.015, 0.05, -0.03, 0.02, 0.02, -0.01, 0.03;
    const Eigen::Vector3d w_m = imu.bg + Eigen::Vector3d(0.4, -0.7, 1.1);
    const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
    ImuValue imu1;
    Matrix15d Phi_II, Q_II;
    const TargetStep mean = propagate_target_imu_step(TargetRepresentation::kGlobal, x, imu, imu_lin, w_m, a_m, 0.1,
                                                      kGravity, ImuNoise{}, noise, &imu1, &Phi_II, &Q_II);
    TargetStep lin = propagate_target(TargetRepresentation::kGlobal, boxplus(x, dx), imu_lin, imu1, Phi_II, Q_II, 0.1,
                                      noise);
    const TargetStep unconstrained = lin;
    const JointNullspace U = joint_unobservable_directions(TargetRepresentation::kGlobal, imu_lin, boxplus(x, dx));
    const JointNullspace W = joint_unobservable_directions(TargetRepresentation::kGlobal, imu1, mean.x);
    constrain_observability(U, W, invariant, &lin);
    Eigen::Matrix<double, 27, 27> Phi;
    joint_transition(Phi_II, Q_II, lin, &Phi, nullptr);
    Eigen::MatrixXd U_c(27, invariant.size()), W_c(27, invariant.size());
    for (size_t i = 0; i < invariant.size(); ++i) {
      U_c.col(static_cast<Eigen::Index>(i)) = U.col(invariant[i]);
      W_c.col(static_cast<Eigen::Index>(i)) = W.col(invariant[i]);
    }
    CHECK((Phi * U_c - W_c).bottomRows<12>().cwiseAbs().maxCoeff() < 1e-12);
    Eigen::Matrix<double, 12, 27> change;
    change << lin.Phi_TI - unconstrained.Phi_TI, lin.Phi_TT - unconstrained.Phi_TT;
    const Eigen::MatrixXd P_U = U_c * (U_c.transpose() * U_c).inverse() * U_c.transpose();
    CHECK(change.cwiseAbs().maxCoeff() > 1e-6);
    CHECK((change - change * P_U).cwiseAbs().maxCoeff() < 1e-12);
  }
  TargetStep step;
  CHECK_THROWS_AS(constrain_observability(JointNullspace::Zero(), JointNullspace::Zero(), {10}, &step),
                  std::invalid_argument);
}

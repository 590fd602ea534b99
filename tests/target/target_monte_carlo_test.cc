// Consistency of Φ and Q against a Monte-Carlo simulation of the continuous
// noise: the sample covariance of the propagated error must match Φ P Φᵀ + Q.
#include <catch2/catch.hpp>

#include <Eigen/Cholesky>
#include <cmath>
#include <random>

#include "common/estimator/propagator.h"
#include "common/math/quat.h"
#include "common/target/target_model.h"
#include "target_test_util.h"

using namespace vimot;
using namespace vimot::target;
using vimot::estimator::ImuNoise;
using vimot::estimator::ImuValue;

namespace {

const Eigen::Vector3d kGravity(0.0, 0.0, 9.81);

struct Gauss {
  explicit Gauss(unsigned seed) : rng(seed) {}
  std::mt19937_64 rng;
  std::normal_distribution<double> n{0.0, 1.0};
  Eigen::VectorXd vec(int k) {
    Eigen::VectorXd v(k);
    for (int i = 0; i < k; ++i) v(i) = n(rng);
    return v;
  }
};

// Fine-step truth of a global target with continuous white noise on v̇, ẇ:
// midpoint rotation for the position, random-walk increments σ √h ξ per substep.
struct TruthTarget {
  Eigen::Matrix3d R_GtoT;
  Eigen::Vector3d p_TinG, v, w;
  void advance(double dt, int substeps, const TargetNoise& tn, Gauss& g) {
    const double h = dt / substeps;
    for (int s = 0; s < substeps; ++s) {
      const Eigen::Matrix3d R_mid = exp_so3(-w * (0.5 * h)) * R_GtoT;
      p_TinG += R_mid.transpose() * v * h;
      R_GtoT = exp_so3(-w * h) * R_GtoT;
      v += tn.sigma_v.cwiseProduct(Eigen::Vector3d(g.vec(3))) * std::sqrt(h);
      w += tn.sigma_w.cwiseProduct(Eigen::Vector3d(g.vec(3))) * std::sqrt(h);
    }
  }
};

// Compares the sample second moment of the errors with P: correlation-normalised
// element differences, normalised mean, and the average NEES.
// Returns the max normalised covariance difference.
double check_consistency(const std::vector<Eigen::VectorXd>& errors, const Eigen::MatrixXd& P, double tol,
                         bool expect_consistent = true) {
  const int n = static_cast<int>(P.rows());
  const double N = static_cast<double>(errors.size());
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(n);
  double nees = 0.0;
  const Eigen::LLT<Eigen::MatrixXd> llt(P);
  REQUIRE(llt.info() == Eigen::Success);
  for (const auto& e : errors) {
    S += e * e.transpose() / N;
    mean += e / N;
    nees += e.dot(llt.solve(e)) / N;
  }
  const Eigen::VectorXd sd = P.diagonal().cwiseSqrt();
  double worst = 0.0, worst_mean = 0.0;
  for (int i = 0; i < n; ++i) {
    worst_mean = std::max(worst_mean, std::abs(mean(i)) / sd(i));
    for (int j = 0; j < n; ++j) worst = std::max(worst, std::abs(S(i, j) - P(i, j)) / (sd(i) * sd(j)));
  }
  INFO("max normalised covariance difference " << worst << ", max normalised mean " << worst_mean
                                               << ", average NEES " << nees << " (dim " << n << ")");
  if (expect_consistent) {
    CHECK(worst < tol);
    CHECK(worst_mean < tol);
    CHECK(std::abs(nees - n) < 0.04 * n);
  }
  return worst;
}

}  // namespace

TEST_CASE("Monte-Carlo: global target covariance matches Phi P Phi^T + Q", "[target][montecarlo]") {
  TargetValue x0 = test::sample_target();
  x0.w_TinT = Eigen::Vector3d(0.2, -0.3, 0.6);
  TargetNoise tn;
  tn.sigma_v = Eigen::Vector3d(0.2, 0.1, 0.15);
  tn.sigma_w = Eigen::Vector3d(0.03, 0.05, 0.08);
  Vector12d sd0;
  sd0 << 0.01, 0.01, 0.01, 0.05, 0.05, 0.05, 0.05, 0.05, 0.05, 0.01, 0.01, 0.01;
  const Matrix12d P0 = sd0.cwiseAbs2().asDiagonal();
  const double dt = 0.05;
  const int steps = 20;

  TargetValue x = x0;
  Matrix12d P = P0;
  for (int k = 0; k < steps; ++k) {
    Matrix12d Phi, Q;
    propagate_global(x, dt, tn, &x, &Phi, &Q);
    P = Phi * P * Phi.transpose() + Q;
  }

  Gauss g(20240611);
  const int N = 4000;
  std::vector<Eigen::VectorXd> errors;
  errors.reserve(N);
  for (int i = 0; i < N; ++i) {
    const TargetValue xt0 = boxplus(x0, Vector12d(sd0.cwiseProduct(Vector12d(g.vec(12)))));
    TruthTarget t{xt0.R_RtoT(), xt0.p_TinR, xt0.v_TinT, xt0.w_TinT};
    for (int k = 0; k < steps; ++k) t.advance(dt, 50, tn, g);
    TargetValue xt;
    xt.q_RtoT = rot_to_quat(t.R_GtoT);
    xt.p_TinR = t.p_TinG;
    xt.v_TinT = t.v;
    xt.w_TinT = t.w;
    errors.push_back(boxminus(xt, x));
  }
  check_consistency(errors, P, 0.1);
}

TEST_CASE("Monte-Carlo: joint IMU + local target covariance matches Phi P Phi^T + Q", "[target][montecarlo]") {
  const ImuValue imu0 = test::sample_imu();
  TargetValue xl0 = test::sample_target();
  xl0.p_TinR = Eigen::Vector3d(4.0, -2.0, 1.0);  // far: the gyro noise couples through [p×]
  xl0.w_TinT = Eigen::Vector3d(0.1, -0.2, 0.4);
  ImuNoise in;
  in.sigma_w = 0.02;
  in.sigma_a = 0.1;
  in.sigma_wb = 1e-3;
  in.sigma_ab = 1e-2;
  TargetNoise tn;
  tn.sigma_v = Eigen::Vector3d::Constant(0.05);
  tn.sigma_w = Eigen::Vector3d::Constant(0.02);
  const Eigen::Vector3d w_m = imu0.bg + Eigen::Vector3d(0.3, -0.5, 0.6);
  const Eigen::Vector3d a_m = imu0.ba + Eigen::Vector3d(0.5, -0.2, 9.9);
  const double dt = 0.01;
  const int steps = 50;

  // Correlated initial covariance.
  Eigen::Matrix<double, 27, 1> sd0;
  sd0 << Eigen::Vector3d::Constant(0.005), Eigen::Vector3d::Constant(0.02), Eigen::Vector3d::Constant(0.02),
      Eigen::Vector3d::Constant(0.002), Eigen::Vector3d::Constant(0.01), Eigen::Vector3d::Constant(0.005),
      Eigen::Vector3d::Constant(0.03), Eigen::Vector3d::Constant(0.02), Eigen::Vector3d::Constant(0.01);
  Gauss g(777);
  Eigen::MatrixXd M = 0.6 * Eigen::MatrixXd::Identity(27, 27);
  for (int i = 0; i < 27; ++i) M.col(i) += 0.4 / std::sqrt(27.0) * g.vec(27);
  Eigen::MatrixXd C = M * M.transpose();
  const Eigen::VectorXd c = C.diagonal().cwiseSqrt().cwiseInverse();
  C = c.asDiagonal() * C * c.asDiagonal();
  const Eigen::MatrixXd P0 = sd0.asDiagonal() * C * sd0.asDiagonal();
  const Eigen::MatrixXd L0 = Eigen::LLT<Eigen::MatrixXd>(P0).matrixL();

  // Filter: mean without noise, joint covariance.
  ImuValue imu = imu0;
  TargetValue xl = xl0;
  Eigen::MatrixXd P = P0;
  Eigen::MatrixXd P_uncoupled = P0;  // negative control: Φ_TI = 0, Q_TI = 0
  for (int k = 0; k < steps; ++k) {
    ImuValue imu1;
    Matrix15d Phi_II, Q_II;
    const TargetStep s = propagate_target_imu_step(TargetRepresentation::kLocal, xl, imu, imu, w_m, a_m, dt,
                                                   kGravity, in, tn, &imu1, &Phi_II, &Q_II);
    Eigen::Matrix<double, 27, 27> Phi, Q;
    joint_transition(Phi_II, Q_II, s, &Phi, &Q);
    P = Phi * P * Phi.transpose() + Q;
    TargetStep s0 = s;
    s0.Phi_TI.setZero();
    s0.Q_TI.setZero();
    joint_transition(Phi_II, Q_II, s0, &Phi, &Q);
    P_uncoupled = Phi * P_uncoupled * Phi.transpose() + Q;
    imu = imu1;
    xl = s.x;
  }

  // Truth: the IMU with its measurement noise held over each sample interval
  // (the estimator's discrete model, variance σ²/dt) and bias random walks;
  // the target in G with continuous noise (fine steps); local = composition.
  const int N = 4000;
  std::vector<Eigen::VectorXd> errors;
  errors.reserve(N);
  for (int i = 0; i < N; ++i) {
    const Eigen::VectorXd e0 = L0 * g.vec(27);
    ImuValue it = estimator::boxplus(imu0, e0.head<15>());
    const TargetValue xlt = boxplus(xl0, Vector12d(e0.tail<12>()));
    const Eigen::Matrix3d R_GtoI0 = quat_to_rot(it.q_GtoI);
    TruthTarget t{xlt.R_RtoT() * R_GtoI0, it.p_IinG + R_GtoI0.transpose() * xlt.p_TinR, xlt.v_TinT, xlt.w_TinT};
    for (int k = 0; k < steps; ++k) {
      const Eigen::Vector3d n_g = in.sigma_w / std::sqrt(dt) * Eigen::Vector3d(g.vec(3));
      const Eigen::Vector3d n_a = in.sigma_a / std::sqrt(dt) * Eigen::Vector3d(g.vec(3));
      ImuValue it1;
      estimator::Propagator::predict_step(it, it, w_m - n_g, a_m - n_a, dt, kGravity, in, &it1, nullptr, nullptr);
      it1.bg += in.sigma_wb * std::sqrt(dt) * Eigen::Vector3d(g.vec(3));
      it1.ba += in.sigma_ab * std::sqrt(dt) * Eigen::Vector3d(g.vec(3));
      it = it1;
      t.advance(dt, 10, tn, g);
    }
    const Eigen::Matrix3d R_GtoI = quat_to_rot(it.q_GtoI);
    TargetValue lt;
    lt.q_RtoT = rot_to_quat(t.R_GtoT * R_GtoI.transpose());
    lt.p_TinR = R_GtoI * (t.p_TinG - it.p_IinG);
    lt.v_TinT = t.v;
    lt.w_TinT = t.w;
    Eigen::VectorXd e(27);
    e << estimator::boxminus(it, imu), boxminus(lt, xl);
    errors.push_back(e);
  }
  check_consistency(errors, P, 0.1);
  // The test is sensitive to the IMU–target coupling: without it the
  // covariance is clearly wrong.
  CHECK(check_consistency(errors, P_uncoupled, 0.1, false) > 0.3);
}

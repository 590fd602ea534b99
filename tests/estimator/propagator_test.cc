#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "common/estimator/propagator.h"
#include "common/estimator/state.h"
#include "common/estimator/state_helper.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::estimator;

namespace {

ImuValue test_state() {
  ImuValue x;
  x.q_GtoI = quat_normalize(Eigen::Vector4d(0.1, -0.3, 0.2, 0.9));
  x.p_IinG = Eigen::Vector3d(1.0, -2.0, 0.5);
  x.v_IinG = Eigen::Vector3d(0.8, 0.3, -0.2);
  x.bg = Eigen::Vector3d(0.01, -0.02, 0.015);
  x.ba = Eigen::Vector3d(0.05, 0.1, -0.08);
  return x;
}

}  // namespace

TEST_CASE("IMU state: x ⊞ (y ⊟ x) = y and (x ⊞ δ) ⊟ x = δ", "[propagator]") {
  const ImuValue x = test_state();
  Eigen::Matrix<double, 15, 1> d;
  for (int i = 0; i < 15; ++i) d(i) = 0.05 * (i - 7);
  const ImuValue y = boxplus(x, d);
  CHECK((boxminus(y, x) - d).cwiseAbs().maxCoeff() < 1e-12);
  // The orientation part is the estimator's left error: R_y = Exp(−δθ) R_x.
  CHECK((quat_to_rot(y.q_GtoI) - exp_so3(-d.head<3>()) * quat_to_rot(x.q_GtoI)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((boxplus(x, boxminus(y, x)).to_vector() - y.to_vector()).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("Gamma integrals match numerical quadrature", "[propagator]") {
  for (double scale : {1e-6, 0.3, 8.0}) {
    const Eigen::Vector3d w = scale * Eigen::Vector3d(0.3, -0.5, 0.8);
    const double dt = 0.2;
    Eigen::Matrix3d G1, G2;
    Propagator::gamma_integrals(w, dt, &G1, &G2);
    Eigen::Matrix3d N1 = Eigen::Matrix3d::Zero(), N2 = Eigen::Matrix3d::Zero();
    const int n = 20000;  // midpoint rule
    for (int i = 0; i < n; ++i) {
      const double tau = (i + 0.5) * dt / n;
      N1 += exp_so3(w * tau) * dt / n;
      N2 += (dt - tau) * exp_so3(w * tau) * dt / n;
    }
    CHECK((G1 - N1).norm() < 1e-8);
    CHECK((G2 - N2).norm() < 1e-9);
  }
}

TEST_CASE("Propagation Phi equals the numerical Jacobian of the integration", "[propagator]") {
  const ImuValue x = test_state();
  const Eigen::Vector3d g(0.0, 0.0, 9.81);
  for (double rate_scale : {0.0, 1.0, 6.0}) {
    const Eigen::Vector3d w_m = Eigen::Vector3d(0.4, -0.7, 1.1) * rate_scale + x.bg;
    const Eigen::Vector3d a_m(0.7, -0.4, 9.9);
    const double dt = 0.01;
    ImuValue x1;
    Matrix15d Phi, Q;
    Propagator::predict_step(x, x, w_m, a_m, dt, g, ImuNoise{}, &x1, &Phi, &Q);
    Matrix15d num;
    const double eps = 1e-6;
    for (int i = 0; i < 15; ++i) {
      Eigen::Matrix<double, 15, 1> d = Eigen::Matrix<double, 15, 1>::Zero();
      d(i) = eps;
      ImuValue xp, xm;
      Propagator::predict_step(boxplus(x, d), boxplus(x, d), w_m, a_m, dt, g, ImuNoise{}, &xp, nullptr, nullptr);
      Propagator::predict_step(boxplus(x, -d), boxplus(x, -d), w_m, a_m, dt, g, ImuNoise{}, &xm, nullptr, nullptr);
      num.col(i) = (boxminus(xp, x1) - boxminus(xm, x1)) / (2.0 * eps);
    }
    INFO("rate scale " << rate_scale << "\nPhi\n" << Phi << "\nnumerical\n" << num);
    CHECK((Phi - num).cwiseAbs().maxCoeff() < 1e-7);
  }
}

TEST_CASE("Phi over a whole interval equals the numerical Jacobian (multi-step)", "[propagator]") {
  // 20 varying samples through Propagator::propagate, with interpolated ends.
  StateOptions so;
  so.use_fej = false;
  const ImuValue x0 = test_state();
  Propagator prop{PropagatorOptions{}};
  for (int i = 0; i <= 22; ++i) {
    ImuData d;
    d.utime = 1000000 + i * 5000;
    const double t = i * 0.005;
    d.w_IinI = Eigen::Vector3d(0.3 * std::sin(3 * t), 0.5, -0.4 * std::cos(2 * t));
    d.a_IinI = Eigen::Vector3d(0.5 * std::cos(5 * t), 0.2, 9.7 + 0.3 * std::sin(4 * t));
    prop.feed_imu(d);
  }
  const int64_t t0 = 1002000, t1 = 1097000;
  auto run = [&](const ImuValue& start, const Matrix15d& P0, Matrix15d* P1) {
    State st(so);
    StateHelper::reset_imu(st, start, P0);
    st.set_utime(t0);
    REQUIRE(prop.propagate(st, t1).ok);
    if (P1) *P1 = st.cov().block<15, 15>(0, 0);
    return st.imu()->get();
  };
  // P1 = Φ P0 Φᵀ + Q: with P0 = 0 and P0 = I, the difference is Φ Φᵀ.
  Matrix15d Pq, Pi;
  const ImuValue x1 = run(x0, Matrix15d::Zero(), &Pq);
  run(x0, Matrix15d::Identity(), &Pi);
  Matrix15d num;
  const double eps = 1e-6;
  for (int i = 0; i < 15; ++i) {
    Eigen::Matrix<double, 15, 1> d = Eigen::Matrix<double, 15, 1>::Zero();
    d(i) = eps;
    num.col(i) = (boxminus(run(boxplus(x0, d), Matrix15d::Zero(), nullptr), x1) -
                  boxminus(run(boxplus(x0, -d), Matrix15d::Zero(), nullptr), x1)) /
                 (2.0 * eps);
  }
  CHECK(((Pi - Pq) - num * num.transpose()).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("FEJ Phi maps the unobservable directions onto themselves", "[propagator]") {
  // N = [R_GtoI g; -[p×] g; -[v×] g; 0; 0] (yaw) and [0; I; 0; 0; 0] (position).
  const Eigen::Vector3d g(0.0, 0.0, 9.81);
  const ImuValue x = test_state();
  ImuValue x_lin = x;  // first estimate differs from the (updated) estimate
  x_lin.q_GtoI = quat_boxplus(x.q_GtoI, Eigen::Vector3d(0.02, -0.01, 0.03));
  x_lin.p_IinG += Eigen::Vector3d(0.1, 0.2, -0.1);
  x_lin.v_IinG += Eigen::Vector3d(-0.05, 0.02, 0.04);
  ImuValue x1;
  Matrix15d Phi, Q;
  Propagator::predict_step(x, x_lin, Eigen::Vector3d(0.3, -0.2, 0.5), Eigen::Vector3d(0.2, 0.1, 9.8), 0.005, g,
                           ImuNoise{}, &x1, &Phi, &Q);
  auto nullspace = [&](const ImuValue& s) {
    Eigen::Matrix<double, 15, 4> N = Eigen::Matrix<double, 15, 4>::Zero();
    N.block<3, 1>(0, 0) = quat_to_rot(s.q_GtoI) * g;
    N.block<3, 1>(3, 0) = -skew(s.p_IinG) * g;
    N.block<3, 1>(6, 0) = -skew(s.v_IinG) * g;
    N.block<3, 3>(3, 1) = Eigen::Matrix3d::Identity();
    return N;
  };
  CHECK((Phi * nullspace(x_lin) - nullspace(x1)).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("Discrete noise Q_d is symmetric PSD with first-order magnitudes", "[propagator]") {
  ImuNoise n;
  const double dt = 0.005;
  ImuValue x1;
  Matrix15d Phi, Q;
  Propagator::predict_step(test_state(), test_state(), Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0, 0, 9.81),
                           dt, Eigen::Vector3d(0, 0, 9.81), n, &x1, &Phi, &Q);
  CHECK((Q - Q.transpose()).norm() < 1e-20);
  Eigen::SelfAdjointEigenSolver<Matrix15d> es(Q);
  CHECK(es.eigenvalues().minCoeff() > -1e-20);
  CHECK(Q(0, 0) == Approx(n.sigma_w * n.sigma_w * dt).epsilon(1e-3));
  CHECK(Q(6, 6) == Approx(n.sigma_a * n.sigma_a * dt).epsilon(1e-3));
  CHECK(Q(9, 9) == Approx(n.sigma_wb * n.sigma_wb * dt).epsilon(1e-12));
  CHECK(Q(12, 12) == Approx(n.sigma_ab * n.sigma_ab * dt).epsilon(1e-12));
}

TEST_CASE("IMU feed rejects bad samples and reports gaps without crashing", "[propagator]") {
  Propagator prop{PropagatorOptions{}};
  ImuData d;
  d.utime = 1000;
  d.a_IinI = Eigen::Vector3d(0, 0, 9.81);
  CHECK(prop.feed_imu(d) == ImuFeedStatus::kAccepted);
  CHECK(prop.feed_imu(d) == ImuFeedStatus::kRejectedDuplicate);
  ImuData older = d;
  older.utime = 500;
  CHECK(prop.feed_imu(older) == ImuFeedStatus::kRejectedOutOfOrder);
  ImuData bad = d;
  bad.utime = 6000;
  bad.w_IinI.x() = std::numeric_limits<double>::quiet_NaN();
  CHECK(prop.feed_imu(bad) == ImuFeedStatus::kRejectedNonFinite);
  bad.w_IinI.x() = std::numeric_limits<double>::infinity();
  CHECK(prop.feed_imu(bad) == ImuFeedStatus::kRejectedNonFinite);
  ImuData next = d;
  next.utime = 6000;
  CHECK(prop.feed_imu(next) == ImuFeedStatus::kAccepted);
  ImuData late = d;
  late.utime = 506000;  // 0.5 s gap
  CHECK(prop.feed_imu(late) == ImuFeedStatus::kAcceptedAfterGap);
  CHECK(prop.counts().accepted == 3);
  CHECK(prop.counts().duplicate == 1);
  CHECK(prop.counts().out_of_order == 1);
  CHECK(prop.counts().non_finite == 2);
  CHECK(prop.counts().gaps == 1);

  // Propagation across the gap works and says so; beyond the data it holds.
  State st{StateOptions{}};
  StateHelper::reset_imu(st, ImuValue{}, Matrix15d::Identity() * 1e-4);
  st.set_utime(1000);
  PropagationReport r = prop.propagate(st, 400000);
  CHECK(r.ok);
  CHECK(r.gap);
  r = prop.propagate(st, 700000);
  CHECK(r.ok);
  CHECK(r.extrapolated);
  // At rest with a_m = g the state does not move.
  CHECK(st.imu()->get().p_IinG.norm() < 1e-9);
  CHECK(st.imu()->get().v_IinG.norm() < 1e-9);
  // Not after the state time: refused.
  CHECK_FALSE(prop.propagate(st, 700000).ok);
  // Without data: refused.
  Propagator empty{PropagatorOptions{}};
  CHECK_FALSE(empty.propagate(st, 800000).ok);
}

TEST_CASE("Noise-free propagation follows a constant-rate circular motion exactly", "[propagator]") {
  // Body on a horizontal circle, yaw rate ω, body x along the velocity.
  const double w = 0.5, r = 2.0, g = 9.81;
  auto truth = [&](double t, ImuValue* x) {
    const double psi = w * t;
    Eigen::Matrix3d R_ItoG;
    R_ItoG << std::cos(psi + M_PI / 2), -std::sin(psi + M_PI / 2), 0, std::sin(psi + M_PI / 2),
        std::cos(psi + M_PI / 2), 0, 0, 0, 1;
    x->q_GtoI = rot_to_quat(R_ItoG.transpose());
    x->p_IinG = Eigen::Vector3d(r * std::cos(psi), r * std::sin(psi), 1.0);
    x->v_IinG = Eigen::Vector3d(-r * w * std::sin(psi), r * w * std::cos(psi), 0.0);
    const Eigen::Vector3d acc(-r * w * w * std::cos(psi), -r * w * w * std::sin(psi), 0.0);
    return Eigen::Vector3d(R_ItoG.transpose() * (acc + Eigen::Vector3d(0, 0, g)));
  };
  PropagatorOptions opt;
  opt.buffer_s = 20.0;  // all 10 s are fed before propagating
  Propagator prop{opt};
  for (int i = 0; i <= 2000; ++i) {
    ImuData d;
    d.utime = i * 5000;
    ImuValue x;
    d.a_IinI = truth(i * 0.005, &x);
    d.w_IinI = Eigen::Vector3d(0, 0, w);
    prop.feed_imu(d);
  }
  State st{StateOptions{}};
  ImuValue x0;
  truth(0.0, &x0);
  StateHelper::reset_imu(st, x0, Matrix15d::Identity() * 1e-4);
  st.set_utime(0);
  for (int k = 1; k <= 100; ++k) REQUIRE(prop.propagate(st, k * 100000 - 3000).ok);
  ImuValue xt;
  truth(10.0 - 0.003, &xt);
  const ImuValue xe = st.imu()->get();
  // The mean-of-samples hold of the (rotating) specific force is O(dt²).
  CHECK((xe.p_IinG - xt.p_IinG).norm() < 2e-3);
  CHECK((xe.v_IinG - xt.v_IinG).norm() < 1e-3);
  CHECK(rotation_angle_between(quat_to_rot(xe.q_GtoI), quat_to_rot(xt.q_GtoI)) < 1e-9);
}

TEST_CASE("An IMU gap with gap noise: same mean for steady readings, covariance of the unknown motion", "[propagator]") {
  // At rest, level: the readings are gravity's specific force, before and
  // after a 1.2 s gap. Mean: still at rest (interpolated readings are the
  // same); covariance over the gap, to first order: attitude σ_w² T per
  // axis, velocity σ_a² T, position σ_a² T³/3 (white accel noise
  // integrated twice), plus tilt × gravity terms in the horizontal axes.
  PropagatorOptions o;
  o.gap_noise.sigma_w = 0.02;
  o.gap_noise.sigma_a = 0.2;
  Propagator with_gap(o);
  Propagator without(PropagatorOptions{});
  const Eigen::Vector3d f(0.0, 0.0, 9.81);
  for (int64_t t : {int64_t{1'000'000}, int64_t{1'005'000}, int64_t{2'205'000}, int64_t{2'210'000}}) {
    ImuData s;
    s.utime = t;
    s.a_IinI = f;
    with_gap.feed_imu(s);
    without.feed_imu(s);
  }
  ImuValue x0;
  x0.q_GtoI = Eigen::Vector4d(0.0, 0.0, 0.0, 1.0);
  ImuValue x1, y1;
  Matrix15d Phi, Q, Phi0, Q0;
  PropagationReport r, r0;
  REQUIRE(with_gap.predict_interval(x0, x0, 1'000'000, 2'210'000, &x1, &Phi, &Q, &r));
  REQUIRE(without.predict_interval(x0, x0, 1'000'000, 2'210'000, &y1, &Phi0, &Q0, &r0));
  CHECK(r.gap);
  CHECK(r.max_step_s == Approx(1.2));
  CHECK(r.steps > r0.steps);  // sub-steps across the gap
  CHECK((x1.to_vector() - y1.to_vector()).cwiseAbs().maxCoeff() < 1e-12);
  const double T = 1.2;
  const double var_th = o.gap_noise.sigma_w * o.gap_noise.sigma_w * T;
  const double var_v = o.gap_noise.sigma_a * o.gap_noise.sigma_a * T;
  const double var_p = o.gap_noise.sigma_a * o.gap_noise.sigma_a * T * T * T / 3.0;
  // Vertical axis (z): no tilt coupling with gravity along z.
  CHECK(Q(2, 2) == Approx(var_th).epsilon(0.05));
  CHECK(Q(8, 8) == Approx(var_v).epsilon(0.05));
  CHECK(Q(5, 5) == Approx(var_p).epsilon(0.05));
  // Without gap noise the gap adds only the sensor's (orders smaller).
  CHECK(Q0(5, 5) < 1e-3 * var_p);
}

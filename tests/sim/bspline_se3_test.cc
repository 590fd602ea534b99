// BsplineSE3 checked against independent truth: a constant-twist motion
// written in closed form (which the cumulative spline must reproduce
// exactly), and central finite differences of the spline's own pose for
// every analytic derivative.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "common/math/quat.h"
#include "common/sim/bspline_se3.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Rodrigues written out here, independent of the library's exp_so3.
Eigen::Matrix3d rodrigues(const Eigen::Vector3d& w) {
  const double th = w.norm();
  if (th < 1e-12) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(th, w / th).toRotationMatrix();
}

// Pose of a body moving with constant body twist (ω, v) from T0, in closed
// form: R(t) = R0 exp(tω), p(t) = p0 + R0 ∫ exp(sω) v ds.
struct ScrewMotion {
  Eigen::Matrix3d R0;
  Eigen::Vector3d p0, w, v;
  Eigen::Matrix4d pose(double t) const {
    // ∫0^t exp(sω) ds v by Simpson with many intervals: independent of Jl.
    const int n = 2000;
    Eigen::Vector3d integral = Eigen::Vector3d::Zero();
    for (int k = 0; k <= n; ++k) {
      const double s = t * k / n;
      const double weight = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
      integral += weight * rodrigues(s * w) * v;
    }
    integral *= t / (3.0 * n);
    Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
    T.topLeftCorner<3, 3>() = R0 * rodrigues(t * w);
    T.topRightCorner<3, 1>() = p0 + R0 * integral;
    return T;
  }
};

Eigen::Matrix4d random_pose(std::mt19937_64& rng, double angle_scale, double pos_scale) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = rodrigues(angle_scale * Eigen::Vector3d(n(rng), n(rng), n(rng)));
  T.topRightCorner<3, 1>() = pos_scale * Eigen::Vector3d(n(rng), n(rng), n(rng));
  return T;
}

}  // namespace

TEST_CASE("BsplineSE3 reproduces a constant-twist motion exactly, with its exact derivatives") {
  ScrewMotion m;
  m.R0 = rodrigues(Eigen::Vector3d(0.3, -0.2, 0.9));
  m.p0 = Eigen::Vector3d(1.0, -2.0, 0.5);
  m.w = Eigen::Vector3d(0.4, -0.3, 0.7);  // rad/s, body
  m.v = Eigen::Vector3d(1.2, 0.4, -0.3);  // m/s, body
  const BsplineSE3 spline = BsplineSE3::from_function([&m](double t) { return m.pose(t); }, 0.0, 3.0, 0.1);
  CHECK(spline.start_time() == Approx(0.0).margin(1e-12));
  CHECK(spline.end_time() >= 3.0);
  for (double t = 0.0; t <= 3.0; t += 0.0737) {
    const SplineState s = spline.evaluate(t);
    const Eigen::Matrix4d T = m.pose(t);
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    CHECK((s.R_BtoG - R).norm() < 1e-9);
    CHECK((s.p_BinG - T.topRightCorner<3, 1>()).norm() < 1e-9);
    CHECK((s.w_BinB - m.w).norm() < 1e-9);
    CHECK(s.alpha_BinB.norm() < 1e-8);
    // ṗ = R v, p̈ = Ṙ v = R (ω × v).
    CHECK((s.v_BinG - R * m.v).norm() < 1e-9);
    CHECK((s.a_BinG - R * m.w.cross(m.v)).norm() < 1e-8);
  }
}

TEST_CASE("BsplineSE3 analytic derivatives match finite differences on random control poses") {
  std::mt19937_64 rng(7);
  std::vector<Eigen::Matrix4d> control;
  Eigen::Matrix4d T = random_pose(rng, 1.0, 1.0);
  for (int k = 0; k < 12; ++k) {
    control.push_back(T);
    T = T * random_pose(rng, 0.15, 0.3);  // smooth-ish random walk of poses
  }
  const double dt = 0.2;
  const BsplineSE3 spline(-0.5, dt, control);
  const double h = 1e-5;
  const double h2 = 1e-4;  // step of the second difference
  int checked = 0;
  // Times across segments, including points right next to the knots.
  for (double t = spline.start_time() + 2 * h; t < spline.end_time() - 2 * h; t += 0.0313) {
    for (const double tt : {t, std::floor((t + 0.5) / dt) * dt - 0.5 + 3 * h}) {
      if (!spline.valid(tt - 2 * h2) || !spline.valid(tt + 2 * h2)) continue;
      const SplineState s = spline.evaluate(tt);
      const Eigen::Matrix4d Tm = spline.pose(tt - h), Tp = spline.pose(tt + h), T0 = spline.pose(tt);
      const Eigen::Matrix3d R = T0.topLeftCorner<3, 3>();
      // Pose agrees with the pose-only path.
      CHECK((s.R_BtoG - R).norm() < 1e-12);
      CHECK((s.p_BinG - T0.topRightCorner<3, 1>()).norm() < 1e-12);
      // ω_B = vee(Rᵀ Ṙ) with Ṙ by central differences.
      const Eigen::Matrix3d Rdot = (Tp.topLeftCorner<3, 3>() - Tm.topLeftCorner<3, 3>()) / (2 * h);
      const Eigen::Matrix3d W = R.transpose() * Rdot;
      const Eigen::Vector3d w_fd(W(2, 1), W(0, 2), W(1, 0));
      CHECK((s.w_BinB - w_fd).norm() < 1e-6 * (1.0 + w_fd.norm()));
      // α = dω/dt, from the analytic ω at neighbouring times.
      const Eigen::Vector3d alpha_fd = (spline.evaluate(tt + h).w_BinB - spline.evaluate(tt - h).w_BinB) / (2 * h);
      CHECK((s.alpha_BinB - alpha_fd).norm() < 1e-5 * (1.0 + alpha_fd.norm()));
      // v = ṗ, a = p̈ (second central difference of the position).
      const Eigen::Vector3d v_fd = (Tp.topRightCorner<3, 1>() - Tm.topRightCorner<3, 1>()) / (2 * h);
      CHECK((s.v_BinG - v_fd).norm() < 1e-6 * (1.0 + v_fd.norm()));
      const Eigen::Vector3d a_fd = (spline.pose(tt + h2).topRightCorner<3, 1>() - 2.0 * T0.topRightCorner<3, 1>() +
                                    spline.pose(tt - h2).topRightCorner<3, 1>()) /
                                   (h2 * h2);
      CHECK((s.a_BinG - a_fd).norm() < 1e-4 * (1.0 + a_fd.norm()));
      ++checked;
    }
  }
  CHECK(checked > 50);
}

TEST_CASE("BsplineSE3 is C2 across knots: velocity and acceleration are continuous") {
  std::mt19937_64 rng(3);
  std::vector<Eigen::Matrix4d> control;
  for (int k = 0; k < 8; ++k) control.push_back(random_pose(rng, 0.3, 0.5));
  const BsplineSE3 spline(0.0, 0.5, control);
  for (int knot = 2; knot <= 5; ++knot) {
    const double t = 0.5 * knot;
    const SplineState a = spline.evaluate(t - 1e-9), b = spline.evaluate(t + 1e-9);
    CHECK((a.w_BinB - b.w_BinB).norm() < 1e-6);
    CHECK((a.alpha_BinB - b.alpha_BinB).norm() < 1e-6);
    CHECK((a.v_BinG - b.v_BinG).norm() < 1e-6);
    CHECK((a.a_BinG - b.a_BinG).norm() < 1e-6);
  }
}

TEST_CASE("BsplineSE3 refuses times outside its valid range and bad construction") {
  std::vector<Eigen::Matrix4d> control(5, Eigen::Matrix4d::Identity());
  const BsplineSE3 spline(10.0, 0.1, control);
  CHECK(spline.start_time() == Approx(10.1));
  CHECK(spline.end_time() == Approx(10.3));
  CHECK_THROWS_AS(spline.evaluate(10.05), std::out_of_range);
  CHECK_THROWS_AS(spline.evaluate(10.31), std::out_of_range);
  CHECK_NOTHROW(spline.evaluate(10.3));
  CHECK_THROWS_AS(BsplineSE3(0.0, 0.1, std::vector<Eigen::Matrix4d>(3, Eigen::Matrix4d::Identity())),
                  std::invalid_argument);
  CHECK_THROWS_AS(BsplineSE3(0.0, -0.1, control), std::invalid_argument);
}

TEST_CASE("BsplineSE3::fit of timed poses follows a constant-velocity motion and starts one dt in") {
  // Irregularly timed samples of p = p0 + v t with a fixed rotation: a
  // one-parameter subgroup, so the fitted spline is exact.
  const Eigen::Vector3d p0(1, 2, 3), v(0.5, -0.25, 0.1);
  const Eigen::Matrix3d R = rodrigues(Eigen::Vector3d(0.1, 0.2, 0.3));
  std::vector<TimedPose> poses;
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> jitter(0.02, 0.08);
  for (double t = 0.0; t < 5.0; t += jitter(rng)) poses.push_back({t, R, p0 + v * t});
  const BsplineSE3 spline = BsplineSE3::fit(poses, 0.05);
  CHECK(spline.start_time() == Approx(0.05));
  for (double t = spline.start_time(); t < spline.end_time(); t += 0.0411) {
    const SplineState s = spline.evaluate(t);
    CHECK((s.p_BinG - (p0 + v * t)).norm() < 1e-9);
    CHECK((s.v_BinG - v).norm() < 1e-9);
    CHECK(s.a_BinG.norm() < 1e-8);
    CHECK((s.R_BtoG - R).norm() < 1e-12);
  }
  std::vector<TimedPose> bad = poses;
  bad[3].t = bad[2].t;
  CHECK_THROWS_AS(BsplineSE3::fit(bad, 0.05), std::invalid_argument);
}

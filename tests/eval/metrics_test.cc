// vimot_eval metrics against hand-computed values; the start-from-truth
// helper against VioEstimator's own initial covariance and N(0, P0).
#include <catch2/catch.hpp>

#include <cmath>
#include <set>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/eval/alignment.h"
#include "common/eval/metrics.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::eval;
using estimator::InitialEstimate;
using estimator::initial_estimate;
using estimator::perturb_seed_for_run;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {
constexpr double kDeg = 180.0 / M_PI;

Eigen::Vector4d quat_of(const Eigen::Matrix3d& R) { return rot_to_quat(R); }
}  // namespace

TEST_CASE("Orientation error is the left error: R_true = Exp(-dtheta) R_est", "[eval][metrics]") {
  const Eigen::Vector3d d(0.0, 0.0, 0.1);
  // Estimate at identity, truth rotated by Exp(-d).
  Eigen::Vector3d e = orientation_error(quat_of(exp_so3(-d)), Eigen::Vector4d(0, 0, 0, 1));
  CHECK_THAT(e.x(), WithinAbs(0.0, 1e-12));
  CHECK_THAT(e.y(), WithinAbs(0.0, 1e-12));
  CHECK_THAT(e.z(), WithinAbs(0.1, 1e-12));
  // Any estimate; the error is the same left perturbation.
  const Eigen::Matrix3d R_est = exp_so3(Eigen::Vector3d(0.3, -1.2, 2.0));
  const Eigen::Vector3d d2(0.02, -0.01, 0.005);
  e = orientation_error(quat_of(exp_so3(-d2) * R_est), quat_of(R_est));
  CHECK((e - d2).norm() < 1e-12);
  // quat_boxplus is the estimator's ⊞: truth = est ⊞ d  ->  error d.
  e = orientation_error(quat_boxplus(quat_of(R_est), d2), quat_of(R_est));
  CHECK((e - d2).norm() < 1e-12);
}

TEST_CASE("NEES and 3-sigma bounds by hand", "[eval][metrics]") {
  Eigen::Matrix3d P_p = Eigen::Vector3d(1.0, 4.0, 4.0).asDiagonal();
  Eigen::Matrix3d P_t = Eigen::Vector3d(1e-4, 1e-4, 4e-4).asDiagonal();
  const Eigen::Vector4d q_true = quat_of(exp_so3(-Eigen::Vector3d(0.01, 0.0, 0.02)));
  const ErrorSample s = compute_error(42, q_true, Eigen::Vector3d(11, 22, 32), Eigen::Vector4d(0, 0, 0, 1),
                                      Eigen::Vector3d(10, 20, 30), P_t, P_p);
  CHECK(s.utime == 42);
  CHECK((s.err_p - Eigen::Vector3d(1, 2, 2)).norm() < 1e-12);
  // 1²/1 + 2²/4 + 2²/4 = 3
  CHECK_THAT(s.nees_p, WithinAbs(3.0, 1e-12));
  // 0.01²/1e-4 + 0 + 0.02²/4e-4 = 2
  CHECK_THAT(s.nees_theta, WithinAbs(2.0, 1e-9));
  CHECK((s.sig3_p - Eigen::Vector3d(3, 6, 6)).norm() < 1e-12);
  CHECK((s.sig3_theta - Eigen::Vector3d(0.03, 0.03, 0.06)).norm() < 1e-12);

  // A full (correlated) covariance: e = [1 1 0], P = [[2 1 0],[1 2 0],[0 0 1]]:
  // P⁻¹ = 1/3 [[2 -1 0],[-1 2 0],[0 0 3]] -> eᵀP⁻¹e = (2 - 1 - 1 + 2)/3 = 2/3.
  Eigen::Matrix3d P;
  P << 2, 1, 0, 1, 2, 0, 0, 0, 1;
  CHECK_THAT(nees3(Eigen::Vector3d(1, 1, 0), P), WithinAbs(2.0 / 3.0, 1e-12));
  // Not positive definite: refused.
  Eigen::Matrix3d bad = Eigen::Matrix3d::Identity();
  bad(2, 2) = -1.0;
  CHECK_THROWS_AS(nees3(Eigen::Vector3d(1, 0, 0), bad), std::invalid_argument);
  bad(2, 2) = std::nan("");
  CHECK_THROWS_AS(nees3(Eigen::Vector3d(1, 0, 0), bad), std::invalid_argument);
}

TEST_CASE("error_of a NavState uses the [dtheta] and [dp] covariance blocks", "[eval][metrics]") {
  NavState x;
  x.utime = 7;
  x.p_IinG = Eigen::Vector3d(1, 1, 1);
  x.covariance = Eigen::Matrix<double, 15, 15>::Identity() * 100.0;
  x.covariance.block<3, 3>(0, 0) = Eigen::Matrix3d::Identity() * 0.01;  // δθ
  x.covariance.block<3, 3>(3, 3) = Eigen::Matrix3d::Identity() * 0.25;  // δp
  GroundTruth gt;
  gt.utime = 7;
  gt.p_IinG = Eigen::Vector3d(1.5, 1, 1);
  gt.q_GtoI = quat_of(exp_so3(-Eigen::Vector3d(0.1, 0, 0)));
  const ErrorSample s = error_of(x, gt);
  CHECK_THAT(s.nees_p, WithinAbs(1.0, 1e-12));      // 0.5² / 0.25
  CHECK_THAT(s.nees_theta, WithinAbs(1.0, 1e-12));  // 0.1² / 0.01
}

TEST_CASE("TrajectoryErrors: RMSE and average NEES", "[eval][metrics]") {
  TrajectoryErrors t;
  CHECK(t.summary().count == 0);
  CHECK(t.summary().rmse_position_m == 0.0);
  ErrorSample a, b;
  a.err_p = Eigen::Vector3d(3, 4, 0);  // |.| = 5
  a.err_theta = Eigen::Vector3d(0.01, 0, 0);
  a.nees_p = 1.0;
  a.nees_theta = 2.0;
  b.err_theta = Eigen::Vector3d(0, 0.02, 0);
  b.nees_p = 3.0;
  b.nees_theta = 6.0;
  a.sig3_p = Eigen::Vector3d(3, 6, 0);       // tr P = 1 + 4 = 5 m²
  b.sig3_p = Eigen::Vector3d(0, 0, 3);       // tr P = 1 m²
  a.sig3_theta = Eigen::Vector3d(0, 0.03, 0);  // tr P = 1e-4 rad²
  t.add(a);
  t.add(b);
  const ErrorSummary s = t.summary();
  CHECK(s.count == 2);
  CHECK_THAT(s.rmse_position_m, WithinRel(std::sqrt(25.0 / 2.0), 1e-14));              // 3.5355 m
  CHECK_THAT(s.rmse_orientation_deg, WithinRel(std::sqrt(5e-4 / 2.0) * kDeg, 1e-14));  // 0.9059258°
  CHECK_THAT(s.rmse_orientation_deg, WithinAbs(0.9059258, 1e-6));
  CHECK_THAT(s.nees_position, WithinAbs(2.0, 1e-14));
  CHECK_THAT(s.nees_orientation, WithinAbs(4.0, 1e-14));
  CHECK_THAT(s.predicted_rmse_position_m, WithinRel(std::sqrt(3.0), 1e-14));                  // √((5 + 1) / 2)
  CHECK_THAT(s.predicted_rmse_orientation_deg, WithinRel(std::sqrt(0.5e-4) * kDeg, 1e-14));  // 0.4051°
}

TEST_CASE("Monte-Carlo aggregate: mean and sample std over runs", "[eval][metrics]") {
  const MeanStd m = mean_std({1.0, 2.0, 3.0, 4.0});
  CHECK_THAT(m.mean, WithinAbs(2.5, 1e-15));
  CHECK_THAT(m.std, WithinAbs(std::sqrt(5.0 / 3.0), 1e-15));
  CHECK(mean_std({5.0}).std == 0.0);
  CHECK(mean_std({}).mean == 0.0);

  ErrorSummary r1, r2;
  r1.rmse_position_m = 0.1;
  r1.rmse_orientation_deg = 1.0;
  r1.nees_position = 2.0;
  r1.nees_orientation = 3.0;
  r1.predicted_rmse_position_m = 0.05;
  r1.predicted_rmse_orientation_deg = 0.5;
  r1.count = 10;
  r2.rmse_position_m = 0.3;
  r2.rmse_orientation_deg = 2.0;
  r2.nees_position = 4.0;
  r2.nees_orientation = 5.0;
  r2.predicted_rmse_position_m = 0.15;
  r2.predicted_rmse_orientation_deg = 1.5;
  r2.count = 20;
  const MonteCarloSummary mc = aggregate(std::vector<ErrorSummary>{r1, r2});
  CHECK(mc.runs == 2);
  CHECK(mc.samples == 30);
  CHECK_THAT(mc.rmse_position_m.mean, WithinAbs(0.2, 1e-15));
  CHECK_THAT(mc.rmse_position_m.std, WithinAbs(std::sqrt(0.02), 1e-15));
  CHECK_THAT(mc.rmse_orientation_deg.mean, WithinAbs(1.5, 1e-15));
  CHECK_THAT(mc.nees_position.mean, WithinAbs(3.0, 1e-15));
  CHECK_THAT(mc.nees_orientation.mean, WithinAbs(4.0, 1e-15));
  CHECK_THAT(mc.predicted_rmse_position_m.mean, WithinAbs(0.1, 1e-15));
  CHECK_THAT(mc.predicted_rmse_orientation_deg.mean, WithinAbs(1.0, 1e-15));
}

TEST_CASE("Timing statistics: mean, median, nearest-rank p95, max", "[eval][metrics]") {
  TimingStats t = timing_stats({5, 1, 4, 2, 3});
  CHECK(t.count == 5);
  CHECK(t.mean_ms == 3.0);
  CHECK(t.median_ms == 3.0);
  CHECK(t.p95_ms == 5.0);
  CHECK(t.max_ms == 5.0);
  CHECK(timing_stats({1, 2, 3, 4}).median_ms == 2.5);
  std::vector<double> v;
  for (int i = 1; i <= 20; ++i) v.push_back(i);
  CHECK(timing_stats(v).p95_ms == 19.0);  // ceil(0.95·20) = 19th
  CHECK(timing_stats({}).count == 0);
}

TEST_CASE("initial_estimate: P0 as VioEstimator builds it, truth for seed 0", "[eval][init]") {
  estimator::VioOptions o = estimator::VioOptions::from_config(
      Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/euroc_stereo.yaml"));
  o.init_sigmas.theta_rp = 0.02;
  o.init_sigmas.theta_yaw = 0.05;
  GroundTruth gt;
  gt.utime = 123;
  gt.q_GtoI = quat_of(exp_so3(Eigen::Vector3d(0.4, -0.3, 1.1)));
  gt.p_IinG = Eigen::Vector3d(1, 2, 3);
  gt.v_IinG = Eigen::Vector3d(0.5, 0, 0);
  gt.bias_gyro = Eigen::Vector3d(1e-3, 0, 0);
  gt.bias_accel = Eigen::Vector3d(0, 0.01, 0);

  const InitialEstimate x0 = initial_estimate(gt, o, 0);
  CHECK(x0.value.q_GtoI == quat_normalize(gt.q_GtoI));
  CHECK(x0.value.p_IinG == gt.p_IinG);
  CHECK(x0.value.v_IinG == gt.v_IinG);
  CHECK(x0.value.bg == gt.bias_gyro);
  CHECK(x0.value.ba == gt.bias_accel);

  estimator::VioEstimator est(o);
  est.initialize(x0.value, gt.utime);  // the estimator's own P0 from init_sigmas
  CHECK((est.imu_covariance() - x0.P0).cwiseAbs().maxCoeff() < 1e-18);
  // Yaw is about G's z: z_G expressed in I has variance σ_yaw² along it.
  const Eigen::Vector3d zI = quat_to_rot(gt.q_GtoI) * Eigen::Vector3d::UnitZ();
  CHECK_THAT(zI.dot(x0.P0.block<3, 3>(0, 0) * zI), WithinRel(0.05 * 0.05, 1e-12));
}

TEST_CASE("initial_estimate: deterministic samples of N(0, P0)", "[eval][init]") {
  estimator::VioOptions o;
  GroundTruth gt;
  gt.q_GtoI = quat_of(exp_so3(Eigen::Vector3d(0.4, -0.3, 1.1)));
  const InitialEstimate a = initial_estimate(gt, o, 17);
  const InitialEstimate b = initial_estimate(gt, o, 17);
  const InitialEstimate c = initial_estimate(gt, o, 18);
  CHECK(a.value.to_vector() == b.value.to_vector());
  CHECK(a.value.to_vector() != c.value.to_vector());
  CHECK(a.P0 == initial_estimate(gt, o, 0).P0);

  // Sample covariance of x̂0 ⊟ x0 over many seeds ≈ P0.
  const int n = 4000;
  Eigen::Matrix<double, 15, 15> S = Eigen::Matrix<double, 15, 15>::Zero();
  for (int k = 1; k <= n; ++k) {
    const InitialEstimate x = initial_estimate(gt, o, perturb_seed_for_run(static_cast<uint64_t>(k)));
    Eigen::Matrix<double, 15, 1> d;
    d.segment<3>(0) = orientation_error(x.value.q_GtoI, gt.q_GtoI);  // x̂ = x ⊞ d -> R̂ = Exp(−d) R
    d.segment<3>(3) = x.value.p_IinG - gt.p_IinG;
    d.segment<3>(6) = x.value.v_IinG - gt.v_IinG;
    d.segment<3>(9) = x.value.bg - gt.bias_gyro;
    d.segment<3>(12) = x.value.ba - gt.bias_accel;
    S += d * d.transpose() / n;
  }
  for (int i = 0; i < 15; ++i) {
    INFO("diagonal " << i);
    CHECK_THAT(S(i, i), WithinRel(a.P0(i, i), 0.1));  // 4000 samples: ±2.2% (1σ)
  }
  // The NEES of the initial error averages 15.
  double nees = 0.0;
  for (int k = 1; k <= 500; ++k) {
    const InitialEstimate x = initial_estimate(gt, o, perturb_seed_for_run(static_cast<uint64_t>(k)));
    Eigen::Matrix<double, 15, 1> d;
    d << orientation_error(x.value.q_GtoI, gt.q_GtoI), x.value.p_IinG - gt.p_IinG, x.value.v_IinG - gt.v_IinG,
        x.value.bg - gt.bias_gyro, x.value.ba - gt.bias_accel;
    nees += d.dot(a.P0.ldlt().solve(d)) / 500.0;
  }
  CHECK(nees > 14.0);
  CHECK(nees < 16.0);
}

TEST_CASE("Perturbation seeds of runs are distinct and never 0", "[eval][init]") {
  std::set<uint64_t> seen;
  for (uint64_t s = 0; s < 1000; ++s) {
    const uint64_t p = perturb_seed_for_run(s);
    CHECK(p != 0);
    seen.insert(p);
  }
  CHECK(seen.size() == 1000);
}

TEST_CASE("4-DoF alignment recovers yaw and translation", "[eval][metrics]") {
  const double yaw = 0.3;
  Eigen::Matrix3d Rz;
  Rz << std::cos(yaw), -std::sin(yaw), 0, std::sin(yaw), std::cos(yaw), 0, 0, 0, 1;
  const Eigen::Vector3d t(1.0, -2.0, 0.5);
  std::vector<PosePair> pairs;
  for (int k = 0; k < 20; ++k) {
    PosePair p;
    p.p_IinG_true = Eigen::Vector3d(std::cos(0.3 * k) * k, std::sin(0.2 * k) * 3.0, 0.1 * k);
    p.q_GtoI_true = rot_to_quat(exp_so3(Eigen::Vector3d(0.1 * k, -0.05 * k, 0.2)));
    // The estimate is the truth seen from a frame rotated by −yaw, shifted.
    p.p_IinG_est = Rz.transpose() * (p.p_IinG_true - t);
    p.q_GtoI_est = rot_to_quat(quat_to_rot(p.q_GtoI_true) * Rz);  // R_ItoG_est = Rzᵀ R_ItoG
    pairs.push_back(p);
  }
  const AlignedErrors a = aligned_errors(pairs);
  CHECK_THAT(a.alignment.yaw, WithinAbs(yaw, 1e-12));
  CHECK((a.alignment.t - t).norm() < 1e-12);
  CHECK(a.ate_position_m < 1e-12);
  CHECK(a.ate_orientation_deg < 1e-6);
  CHECK(a.count == 20);
  // A constant shift is absorbed by the translation; a roll error is not.
  for (auto& p : pairs) p.p_IinG_est += Eigen::Vector3d(0, 0, 0.1);
  CHECK(aligned_errors(pairs).ate_position_m < 1e-12);
  for (auto& p : pairs) p.q_GtoI_est = quat_boxplus(p.q_GtoI_est, Eigen::Vector3d(0.01, 0, 0));
  CHECK_THAT(aligned_errors(pairs).ate_orientation_deg, WithinAbs(0.01 * kDeg, 1e-9));
  CHECK(aligned_errors({}).count == 0);
}

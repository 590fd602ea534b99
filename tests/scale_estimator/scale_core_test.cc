// Scale estimator core: Eq. 12-14 and the Eq. 19 figures against values
// computed by hand, the non-uniform finite differences of Eq. 8-9, Eq. 20-21,
// the sliding window, input rejection and the options.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>

#include "common/config/config.h"
#include "common/math/quat.h"
#include "common/object/scale_estimator.h"

using namespace vimot;
using namespace vimot::scale;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

ScaleEstimatorOptions small_window(int n = 5) {
  ScaleEstimatorOptions o;
  o.window_size = n;
  o.min_observations = n;
  return o;
}

Eigen::Matrix3d rot_z(double a) { return exp_so3(Eigen::Vector3d(0.0, 0.0, a)); }

}  // namespace

TEST_CASE("scale_core: Eq. 12-14 and Eq. 19 figures on a hand-computed set", "[scale]") {
  // Three motion samples (k = 1..3):
  //   m_c = (1,0,0), (2,0,0), (3,0,0)        mean (2,0,0), deviations x: -1, 0, 1
  //   m_d = (2,1,0), (1.5,0,0), (0.5,0,0)    mean (4/3,1/3,0)
  //                                          deviations x: 2/3, 1/6, -5/6
  //                                          deviations y: 2/3, -1/3, -1/3
  // Eq. 12 with 1/(N_o - 1) = 1/2:
  //   C_xx = Cov(m_c^x, m_c^x) = (1 + 0 + 1)/2 = 1, every other C_ij = 0
  //   D_xx = Cov(m_d^x, m_c^x) = (-2/3 + 0 - 5/6)/2 = -3/4
  //   D_yx = Cov(m_d^y, m_c^x) = (-2/3 + 0 - 1/3)/2 = -1/2, every other D_ij = 0
  // Eq. 14: s* = -(D_xx C_xx) / (D_xx^2 + D_yx^2) = (3/4) / (9/16 + 4/16) = 12/13
  // Eq. 13: f(s*) = (s* D_xx + C_xx)^2 + (s* D_yx)^2
  //               = (1 - 9/13)^2 + (6/13)^2 = 16/169 + 36/169 = 4/13
  // Eq. 19 figures: (i) 4/13, (ii) sum C^2 = 1, (iii) sum D^2 = 13/16.
  const std::vector<Eigen::Vector3d> m_c = {{1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  const std::vector<Eigen::Vector3d> m_d = {{2, 1, 0}, {1.5, 0, 0}, {0.5, 0, 0}};

  ScaleEstimatorOptions o;
  o.epsilon_t1 = 0.5;  // 4/13 = 0.3077 <= 0.5
  o.rho_t1 = 0.9;      // 1 >= 0.9
  o.rho_t2 = 0.8;      // 13/16 = 0.8125 >= 0.8
  ScaleResult r = estimate_scale(m_c, m_d, o);
  CHECK_THAT(r.scale, WithinRel(12.0 / 13.0, 1e-12));
  CHECK_THAT(r.f_value, WithinRel(4.0 / 13.0, 1e-12));
  CHECK_THAT(r.condition[0], WithinRel(4.0 / 13.0, 1e-12));
  CHECK_THAT(r.condition[1], WithinRel(1.0, 1e-12));
  CHECK_THAT(r.condition[2], WithinRel(13.0 / 16.0, 1e-12));
  CHECK_THAT(r.f_relative, WithinRel(4.0 / 13.0, 1e-12));  // / sum C^2 = 1
  CHECK_THAT(r.cov_dc(0, 0), WithinRel(-0.75, 1e-12));
  CHECK_THAT(r.cov_dc(1, 0), WithinRel(-0.5, 1e-12));
  CHECK(r.accepted);
  CHECK(r.status == ScaleStatus::kAccepted);
  CHECK(r.failed_condition == 0);
  CHECK(r.num_motion_samples == 3);

  // Eq. 13 is quadratic with its minimum at s*: neighbours cost more.
  auto f = [&](double s) { return (s * r.cov_dc + r.cov_cc).squaredNorm(); };
  CHECK(f(r.scale + 1e-3) > r.f_value);
  CHECK(f(r.scale - 1e-3) > r.f_value);

  // Each threshold on its own side of the hand values; first failure reported.
  o.epsilon_t1 = 0.3;  // 4/13 > 0.3: (i) fails
  r = estimate_scale(m_c, m_d, o);
  CHECK_FALSE(r.accepted);
  CHECK(r.failed_condition == 1);
  CHECK(r.condition_ok == std::array<bool, 3>{{false, true, true}});
  o.epsilon_t1 = 0.5;
  o.rho_t1 = 1.1;  // 1 < 1.1: (ii) fails
  r = estimate_scale(m_c, m_d, o);
  CHECK(r.failed_condition == 2);
  CHECK(r.condition_ok == std::array<bool, 3>{{true, false, true}});
  o.rho_t1 = 0.9;
  o.rho_t2 = 0.82;  // 0.8125 < 0.82: (iii) fails
  r = estimate_scale(m_c, m_d, o);
  CHECK(r.failed_condition == 3);
  CHECK(r.condition_ok == std::array<bool, 3>{{true, true, false}});

  // Relative (i): f / sum C^2 = 4/13 as well here.
  o.rho_t2 = 0.8;
  o.relative_condition_i = true;
  o.epsilon_t1 = 0.31;
  r = estimate_scale(m_c, m_d, o);
  CHECK(r.accepted);
  CHECK_THAT(r.condition[0], WithinRel(4.0 / 13.0, 1e-12));
}

TEST_CASE("scale_core: s* undefined when m_d does not covary with m_c", "[scale]") {
  // m_d constant -> D = 0: f(s) = sum C^2 for every s; s* = NaN, f = sum C^2.
  const std::vector<Eigen::Vector3d> m_c = {{1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  const std::vector<Eigen::Vector3d> m_d(3, Eigen::Vector3d(1, 2, 3));
  ScaleEstimatorOptions o;
  const ScaleResult r = estimate_scale(m_c, m_d, o);
  CHECK(std::isnan(r.scale));
  CHECK_THAT(r.f_value, WithinRel(1.0, 1e-12));
  CHECK(r.condition[2] == 0.0);
  CHECK_FALSE(r.accepted);
  CHECK(r.failed_condition == 1);  // 1 > eps_t1 = 1e-3
  CHECK_FALSE(r.condition_ok[2]);
}

TEST_CASE("scale_core: non-uniform central differences (Eq. 8-9)", "[scale]") {
  // utimes 0, 0.1, 0.3, 0.4, 0.6 s (steps 0.1, 0.2, 0.1, 0.2). The 3-point
  // non-uniform stencils are exact for quadratics:
  //   x(t) = t^2 -> dx/dt = 2t = 0.2, 0.6, 0.8 at t = 0.1, 0.3, 0.4
  //              -> d2x/dt2 = 2 everywhere
  // By hand at t = 0.1 (h1 = 0.1, h2 = 0.2): weights
  //   n=1: -h2/(h1(h1+h2)) = -20/3, (h2-h1)/(h1 h2) = 5, h1/(h2(h1+h2)) = 5/3
  //        -> -20/3*0 + 5*0.01 + 5/3*0.09 = 0.05 + 0.15 = 0.2
  //   n=2: 2/(h1(h1+h2)) = 200/3, -2/(h1 h2) = -100, 2/(h2(h1+h2)) = 100/3
  //        -> 0 - 1 + 3 = 2
  const std::vector<int64_t> t = {5'000'000'000, 5'000'100'000, 5'000'300'000, 5'000'400'000,
                                  5'000'600'000};
  std::vector<Eigen::Vector3d> x;
  for (int64_t u : t) {
    const double s = 1e-6 * static_cast<double>(u - t[0]);
    x.emplace_back(s * s, 3.0 * s - 1.0, 7.0);
  }
  const auto v = central_difference(t, x, 1);
  const auto a = central_difference(t, x, 2);
  REQUIRE(v.size() == 3);
  REQUIRE(a.size() == 3);
  const double tv[] = {0.1, 0.3, 0.4};
  for (int k = 0; k < 3; ++k) {
    CHECK_THAT(v[k].x(), WithinAbs(2.0 * tv[k], 1e-9));
    CHECK_THAT(v[k].y(), WithinAbs(3.0, 1e-9));
    CHECK_THAT(v[k].z(), WithinAbs(0.0, 1e-9));
    CHECK_THAT(a[k].x(), WithinAbs(2.0, 1e-7));
    CHECK_THAT(a[k].y(), WithinAbs(0.0, 1e-7));
  }
  // Uniform steps: n = 2 is the paper's Eq. 9 (p(t+2Δ) - 2p(t+Δ) + p(t)) / Δ^2.
  const std::vector<int64_t> tu = {0, 50'000, 100'000};
  const std::vector<Eigen::Vector3d> xu = {{1, 0, 0}, {4, 0, 0}, {2, 0, 0}};
  CHECK_THAT(central_difference(tu, xu, 2)[0].x(), WithinAbs((2.0 - 8.0 + 1.0) / 0.0025, 1e-9));
  CHECK_THAT(central_difference(tu, xu, 1)[0].x(), WithinAbs((2.0 - 1.0) / 0.1, 1e-12));
  CHECK_THROWS_AS(central_difference({0, 0, 1}, xu, 1), std::invalid_argument);
  CHECK_THROWS_AS(central_difference(tu, xu, 3), std::invalid_argument);
}

// Samples 1 s apart, x = k^2, y = k, z = (-1)^k. Box of 2 s = 3 samples,
// box of 4 s = 5 samples; only k = 2..4 have the 4 s box inside [0, 6].
// By hand: mean of k^2 over k-1..k+1 is k^2 + 2/3, over k-2..k+2 it is
// k^2 + 2, so x -> -4/3; a linear y is unchanged by both boxes -> 0;
// z: the 3-sample mean of (-1)^j is -(-1)^k / 3, the 5-sample mean
// (-1)^k / 5, so z -> -(-1)^k 8/15.
TEST_CASE("scale_core: band-pass of the motion samples against hand values", "[scale]") {
  std::vector<int64_t> t;
  std::vector<Eigen::Vector3d> m;
  for (int k = 0; k <= 6; ++k) {
    t.push_back(5'000'000'000 + 1'000'000 * k);
    m.emplace_back(k * k, k, k % 2 == 0 ? 1.0 : -1.0);
  }
  const std::vector<Eigen::Vector3d> out = band_pass(t, m, 2.0, 4.0);
  REQUIRE(out.size() == 3);
  for (int i = 0; i < 3; ++i) {
    const int k = i + 2;
    CHECK_THAT(out[i].x(), WithinAbs(-4.0 / 3.0, 1e-12));
    CHECK_THAT(out[i].y(), WithinAbs(0.0, 1e-12));
    CHECK_THAT(out[i].z(), WithinAbs((k % 2 == 0 ? -1.0 : 1.0) * 8.0 / 15.0, 1e-12));
  }
  // High-pass only: m_k minus the 5-sample mean; low-pass only: the 3-sample
  // mean at k = 1..5; neither: unchanged.
  const auto high = band_pass(t, m, 0.0, 4.0);
  REQUIRE(high.size() == 3);
  CHECK_THAT(high[0].x(), WithinAbs(-2.0, 1e-12));
  const auto low = band_pass(t, m, 2.0, 0.0);
  REQUIRE(low.size() == 5);
  CHECK_THAT(low[0].x(), WithinAbs(1.0 + 2.0 / 3.0, 1e-12));
  CHECK(band_pass(t, m, 0.0, 0.0) == m);
  CHECK_THROWS_AS(band_pass(t, std::vector<Eigen::Vector3d>(3), 1.0, 2.0), std::invalid_argument);
  CHECK_THROWS_AS(band_pass(t, m, -1.0, 2.0), std::invalid_argument);
}

// Eq. 8 stays exact under the band-pass: it is linear, so with the object
// at rest (m_o = 0) s* is still exactly s, and a slow object motion that
// covaries with a slow camera term is filtered out. Camera: a slow 0.1 Hz
// swing plus a 1 Hz shake; object: 0.1 Hz in phase with the swing. The
// paper's estimator sees Cov(m_o, m_c) != 0 (Eq. 15) and is biased; the
// band-pass 0.3 s / 2.5 s keeps the 1 Hz shake only.
TEST_CASE("scale_core: the band-pass removes a slow object-camera covariance", "[scale]") {
  const double s_true = 2.0;
  auto run = [&](double lowpass, double highpass, double object_amplitude) {
    ScaleEstimatorOptions o;
    o.window_size = o.min_observations = 400;  // 20 s at 20 Hz
    o.motion_lowpass_s = lowpass;
    o.motion_highpass_s = highpass;
    ScaleEstimator est(o);
    ScaleResult r;
    for (int k = 0; k < 400; ++k) {
      const double t = 0.05 * k;
      const Eigen::Vector3d p_C(0.3 * std::sin(2 * M_PI * 0.1 * t) + 0.05 * std::sin(2 * M_PI * 1.0 * t),
                                0.05 * std::cos(2 * M_PI * 1.0 * t), 0.0);
      const Eigen::Vector3d p_O(3.0 + object_amplitude * std::sin(2 * M_PI * 0.1 * t), 0.0, 0.0);
      ScaleObservation obs = ScaleObservation::from_rotations(1'000'000 + 50'000 * k, Eigen::Matrix3d::Identity(),
                                                              p_C, Eigen::Matrix3d::Identity(), (p_O - p_C) / s_true);
      REQUIRE(is_added(est.add(obs)));
      r = est.update();
    }
    REQUIRE(r.status != ScaleStatus::kInsufficientData);
    return r.scale / s_true - 1.0;
  };
  // Object at rest: exact with and without the band-pass.
  CHECK_THAT(run(0.0, 0.0, 0.0), WithinAbs(0.0, 1e-9));
  CHECK_THAT(run(0.3, 2.5, 0.0), WithinAbs(0.0, 1e-9));
  // Object swinging with the camera's slow term.
  const double paper = run(0.0, 0.0, 0.2);
  const double band = run(0.3, 2.5, 0.2);
  INFO("paper " << paper << ", band-pass " << band);
  CHECK(std::abs(paper) > 0.1);
  CHECK(std::abs(band) < 0.01);
}

TEST_CASE("scale_core: pipeline on 5 hand-made observations, rotated camera", "[scale]") {
  // Same utimes as above. Camera: p_CinG = (t^2, 0, 0), R_CtoG = Rz(90 deg)
  // constant. Object offset in the world chosen as p_d^w = (1 - t^2/2, 0, 1),
  // i.e. pbar_OinC = R_CtoG^T p_d^w = (0, -(1 - t^2/2), 1).
  // Interior samples t = 0.1, 0.3, 0.4:
  //   m_c = (2t, 0, 0) = (0.2,0,0), (0.6,0,0), (0.8,0,0)
  //   m_d = (-t, 0, 0) = -m_c / 2
  //   C_xx = Var(0.2, 0.6, 0.8) = 0.04 * Var(1, 3, 4) = 0.04 * (14/3)/2 = 7/75
  //   D_xx = -C_xx / 2 = -7/150
  //   s* = -(D_xx C_xx)/D_xx^2 = -C_xx/D_xx = 2,  f(s*) = (2 D_xx + C_xx)^2 = 0
  //   (ii) = (7/75)^2 = 49/5625,  (iii) = (7/150)^2 = 49/22500
  // A transposed camera rotation would give p_d^w = (-(1 - t^2/2), 0, 1)
  // and s* = -2.
  const std::vector<int64_t> t = {5'000'000'000, 5'000'100'000, 5'000'300'000, 5'000'400'000,
                                  5'000'600'000};
  ScaleEstimatorOptions o = small_window(5);
  o.epsilon_t1 = 1e-12;
  o.rho_t1 = 8e-3;    // 49/5625 = 8.71e-3
  o.rho_t2 = 2e-3;    // 49/22500 = 2.18e-3
  ScaleEstimator est(o);
  for (int64_t u : t) {
    const double s = 1e-6 * static_cast<double>(u - t[0]);
    const auto obs = ScaleObservation::from_rotations(u, rot_z(M_PI / 2), Eigen::Vector3d(s * s, 0, 0),
                                                      Eigen::Matrix3d::Identity(),
                                                      Eigen::Vector3d(0, -(1 - s * s / 2), 1));
    REQUIRE(est.add(obs) == AddStatus::kAdded);
  }
  const ScaleResult r = est.update();
  CHECK(r.num_observations == 5);
  CHECK(r.num_motion_samples == 3);
  CHECK(r.utime == t.back());
  CHECK_THAT(r.scale, WithinRel(2.0, 1e-9));
  CHECK_THAT(r.f_value, WithinAbs(0.0, 1e-15));
  CHECK_THAT(r.condition[1], WithinRel(49.0 / 5625.0, 1e-9));
  CHECK_THAT(r.condition[2], WithinRel(49.0 / 22500.0, 1e-9));
  CHECK(r.accepted);
  CHECK(est.has_scale());
  CHECK_THAT(est.scale(), WithinRel(2.0, 1e-9));

  // Eq. 20-21 on the newest observation (t = 0.6): p_OinC = 2 * (0, -0.82, 1),
  // p_OinG = Rz(90) p_OinC + (0.36, 0, 0) = (1.64 + 0.36, 0, 2) = (2, 0, 2).
  const auto pose = est.latest_object_pose();
  REQUIRE(pose);
  CHECK(pose->utime == t.back());
  CHECK(pose->p_OinC.isApprox(Eigen::Vector3d(0, -1.64, 2), 1e-9));
  CHECK(pose->p_OinG.isApprox(Eigen::Vector3d(2.0, 0, 2), 1e-9));
  CHECK(pose->R_OtoG.isApprox(rot_z(M_PI / 2), 1e-12));
  CHECK(quat_to_rot(pose->q_GtoO).isApprox(rot_z(M_PI / 2).transpose(), 1e-12));
}

TEST_CASE("scale_core: Eq. 21 composes rotations and positions", "[scale]") {
  const Eigen::Matrix3d R_CtoG = exp_so3(Eigen::Vector3d(0.3, -0.2, 1.1));
  const Eigen::Matrix3d R_OtoC = exp_so3(Eigen::Vector3d(-0.5, 0.4, 0.2));
  const Eigen::Vector3d p_CinG(1, 2, 3), pbar(0.1, -0.2, 1.0);
  const auto obs = ScaleObservation::from_rotations(7, R_CtoG, p_CinG, R_OtoC, pbar);
  CHECK(obs.R_CtoG().isApprox(R_CtoG, 1e-12));
  CHECK(obs.p_d_in_G().isApprox(R_CtoG * pbar, 1e-12));
  const ObjectPoseInWorld p = object_pose_in_world(2.5, obs);
  CHECK(p.R_OtoG.isApprox(R_CtoG * R_OtoC, 1e-12));
  CHECK(quat_to_rot(p.q_GtoO).isApprox((R_CtoG * R_OtoC).transpose(), 1e-12));
  CHECK(p.p_OinC.isApprox(2.5 * pbar, 1e-12));
  CHECK(p.p_OinG.isApprox(2.5 * R_CtoG * pbar + p_CinG, 1e-12));
  CHECK(p.utime == 7);
}

TEST_CASE("scale_core: the sliding window keeps the newest N_o observations", "[scale]") {
  ScaleEstimatorOptions o;
  o.window_size = 10;
  o.min_observations = 6;
  ScaleEstimator est(o);
  for (int k = 0; k < 25; ++k) {
    ScaleObservation obs;
    obs.utime = 1'000'000 + k * 50'000;
    obs.p_CinG = Eigen::Vector3d(std::sin(k), 0, 0);
    obs.pbar_OinC = Eigen::Vector3d(0, 0, 1);
    CHECK(est.add(obs) == AddStatus::kAdded);
    const ScaleResult r = est.update();
    CHECK(r.num_observations == std::min(k + 1, 10));
    if (k + 1 < 6) {
      CHECK(r.status == ScaleStatus::kInsufficientData);
      CHECK_FALSE(r.accepted);
    } else {
      CHECK(r.status != ScaleStatus::kInsufficientData);
      CHECK(r.num_motion_samples == r.num_observations - 2);
    }
  }
  CHECK(est.window().size() == 10);
  CHECK(est.window().front().utime == 1'000'000 + 15 * 50'000);
  CHECK(est.window().back().utime == 1'000'000 + 24 * 50'000);
  CHECK(est.stats().added == 25);
}

TEST_CASE("scale_core: bad input is rejected and reported, the window unchanged", "[scale]") {
  ScaleEstimator est(small_window(5));
  ScaleObservation good;
  good.utime = 1'000'000;
  good.pbar_OinC = Eigen::Vector3d(0, 0, 1);
  REQUIRE(est.add(good) == AddStatus::kAdded);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  ScaleObservation b = good;
  b.utime = 2'000'000;
  b.p_CinG.x() = nan;
  CHECK(est.add(b) == AddStatus::kRejectedNonFinite);
  b = good;
  b.utime = 2'000'000;
  b.pbar_OinC.z() = std::numeric_limits<double>::infinity();
  CHECK(est.add(b) == AddStatus::kRejectedNonFinite);
  b = good;
  b.utime = 2'000'000;
  b.q_OtoC(3) = nan;
  CHECK(est.add(b) == AddStatus::kRejectedNonFinite);
  b = good;
  b.utime = 2'000'000;
  b.q_GtoC = Eigen::Vector4d(0, 0, 0, 2);  // not a rotation
  CHECK(est.add(b) == AddStatus::kRejectedBadQuaternion);
  b = good;  // duplicate utime
  CHECK(est.add(b) == AddStatus::kRejectedDuplicateTime);
  b.utime = 999'999;  // time going backwards
  CHECK(est.add(b) == AddStatus::kRejectedTimeBackwards);
  CHECK(est.window().size() == 1);
  CHECK(est.stats().rejected_non_finite == 3);
  CHECK(est.stats().rejected_bad_quaternion == 1);
  CHECK(est.stats().rejected_duplicate_time == 1);
  CHECK(est.stats().rejected_time_backwards == 1);
  CHECK(std::string(to_string(AddStatus::kRejectedTimeBackwards)) == "rejected_time_backwards");

  // A slightly off-unit quaternion is normalised, not rejected.
  b = good;
  b.utime = 1'050'000;
  b.q_GtoC = Eigen::Vector4d(0, 0, 0, 1.0005);
  CHECK(est.add(b) == AddStatus::kAdded);
  CHECK_THAT(est.window().back().q_GtoC.norm(), WithinAbs(1.0, 1e-15));

  // add_and_update reports the rejection and does not estimate.
  AddStatus st;
  CHECK_FALSE(est.add_and_update(b, &st));
  CHECK(st == AddStatus::kRejectedDuplicateTime);

  // A gap beyond max_gap_s (1 s) clears the window first.
  b.utime = 3'000'000;
  CHECK(est.add(b) == AddStatus::kAddedAfterGap);
  CHECK(est.window().size() == 1);
  CHECK(est.stats().gap_resets == 1);
  // reset() forgets the time ordering too.
  est.reset();
  b.utime = 10;
  CHECK(est.add(b) == AddStatus::kAdded);
}

TEST_CASE("scale_core: options from a config section", "[scale]") {
  const Config cfg = Config::from_string(R"(
scale_estimator:
  window_size: 150
  min_observations: 100
  derivative_order: 2
  motion_lowpass_s: 0.2
  motion_highpass_s: 3.0
  epsilon_t1: 0.01
  rho_t1: 0.5
  rho_t2: 0.02
  relative_condition_i: true
  require_positive_scale: false
  max_gap_s: 0.25
  quat_norm_tolerance: 0.01
)",
                                         "test.yaml");
  const ScaleEstimatorOptions o = ScaleEstimatorOptions::from_config(cfg);
  CHECK(o.window_size == 150);
  CHECK(o.min_observations == 100);
  CHECK(o.derivative_order == 2);
  CHECK(o.motion_lowpass_s == 0.2);
  CHECK(o.motion_highpass_s == 3.0);
  CHECK(o.epsilon_t1 == 0.01);
  CHECK(o.rho_t1 == 0.5);
  CHECK(o.rho_t2 == 0.02);
  CHECK(o.relative_condition_i);
  CHECK_FALSE(o.require_positive_scale);
  CHECK(o.max_gap_s == 0.25);
  CHECK(o.quat_norm_tolerance == 0.01);

  // Absent section: defaults (N_o = 200, n = 1).
  const ScaleEstimatorOptions d = ScaleEstimatorOptions::from_config(Config::from_string("other: 1"));
  CHECK(d.window_size == 200);
  CHECK(d.derivative_order == 1);
  CHECK(d.motion_lowpass_s == 0.0);  // the paper's estimator
  CHECK(d.motion_highpass_s == 0.0);

  CHECK_THROWS_AS(ScaleEstimatorOptions::from_config(
                      Config::from_string("scale_estimator:\n  derivative_order: 3\n")),
                  ConfigError);
  CHECK_THROWS_AS(ScaleEstimatorOptions::from_config(
                      Config::from_string("scale_estimator:\n  window_size: 100\n")),  // < min 200
                  ConfigError);
  CHECK_THROWS_AS(ScaleEstimatorOptions::from_config(Config::from_string(
                      "scale_estimator:\n  motion_lowpass_s: 1.0\n  motion_highpass_s: 0.5\n")),  // empty band
                  ConfigError);
  CHECK_THROWS_AS(ScaleEstimatorOptions::from_config(
                      Config::from_string("scale_estimator:\n  motion_lowpass_s: -0.1\n")),
                  ConfigError);
  CHECK_THROWS_AS(ScaleEstimatorOptions::from_config(
                      Config::from_string("scale_estimator:\n  rho_t1x: 1\n")),  // typo
                  ConfigError);
  CHECK_THROWS_AS(ScaleEstimatorOptions::from_config(
                      Config::from_string("scale_estimator:\n  rho_t1: abc\n")),
                  ConfigError);
  ScaleEstimatorOptions bad;
  bad.min_observations = 3;
  CHECK_THROWS_AS(ScaleEstimator(bad), std::invalid_argument);
}

// AdaptiveNoise (the `adaptive` target mode's σ_t estimate and consistency
// check) on a filter whose truth is exactly its model: three axes, each a
// position measured at 20 Hz and a velocity driven by a random walk of known
// density. The estimate must converge to the true density (also after a
// step), the adaptive filter must be consistent (NEES), and the check must
// flag a model violation (a velocity jump) but not a consistent run.
#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>

#include "common/target/adaptive_noise.h"

using vimot::target::AdaptiveNoise;
using vimot::target::AdaptiveNoiseOptions;

namespace {

constexpr double kDt = 0.05;       // s (20 Hz)
constexpr double kSigmaMeas = 0.01;  // m

struct Axis {
  Eigen::Vector2d x_true{0.0, 1.0};  // p, v
  Eigen::Vector2d x{0.0, 1.0};
  Eigen::Matrix2d P{Eigen::Vector2d(1e-4, 1e-2).asDiagonal()};
};

struct RunResult {
  std::vector<double> sigma;     // σ̂ after each frame
  std::vector<double> matched;   // the windowed estimate before the hold
  std::vector<double> nees;      // Σ over axes of the [p, v] NEES (6 dof)
  std::vector<bool> consistent;  // the check after each frame
  std::vector<double> position_error;  // m, |p_true − p̂| over the axes
  int64_t violations{0};
};

// How the harness uses the estimate beyond its σ (TargetFilter's use): off
// by default (σ only, every measurement used).
struct Use {
  bool gate{false};           // drop the frame's measurements above χ²_0.95(3), as the filter's gate
  bool inflate{false};        // add inflation() after a violating frame
  bool before_update{false};  // and take the σ steps before a violating frame's update
  double accel_from{-1.0};    // [s] the truth accelerates at `accel` on every axis
  double accel_to{-1.0};      //     from accel_from to accel_to (a car speeding up)
  double accel{1.0};          // [m/s²]
};

// Variance of the missed noise over τ (density² = variance / τ) on [p, v]:
// the integrated white noise, as TargetFilter propagates it through the motion.
void add_inflation(const AdaptiveNoise& est, Axis* ax) {
  const double tau = est.inflation_time();
  if (!(est.inflation() > 0.0) || !(tau > 0.0)) return;
  Eigen::Matrix2d Q;
  Q << tau * tau * tau / 3.0, tau * tau / 2.0, tau * tau / 2.0, tau;
  ax->P += est.inflation() / tau * Q;
}

// sigma_true(k): the truth's density at frame k; jump_frame: a velocity jump
// of 2 m/s on every axis there (a collision: outside any random walk), or -1.
template <typename SigmaOf>
RunResult run(uint64_t seed, int frames, double sigma0, SigmaOf sigma_true, int jump_frame = -1,
              const AdaptiveNoiseOptions& options = {}, const Use& use = {}) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  AdaptiveNoise est(options, sigma0);
  Axis axes[3];
  Eigen::Matrix2d F;
  F << 1.0, kDt, 0.0, 1.0;
  RunResult out;
  for (int k = 0; k < frames; ++k) {
    const double s_true = sigma_true(k);
    const double s = est.sigma();
    // Discrete noise of v̇ = n (density s): the exact integrated white noise.
    Eigen::Matrix2d Q;
    Q << kDt * kDt * kDt / 3.0, kDt * kDt / 2.0, kDt * kDt / 2.0, kDt;
    Eigen::VectorXd xm(3), Pm(3), xp(3), Pp(3);
    double z[3];
    const double t = k * kDt;
    const double accel = t >= use.accel_from && t < use.accel_to ? use.accel : 0.0;
    for (int a = 0; a < 3; ++a) {
      Axis& ax = axes[a];
      // Truth: fine steps of the continuous random walk.
      const int sub = 10;
      const double h = kDt / sub;
      for (int i = 0; i < sub; ++i) {
        const double dv = s_true * std::sqrt(h) * n01(rng) + accel * h;
        ax.x_true(0) += (ax.x_true(1) + 0.5 * dv) * h;
        ax.x_true(1) += dv;
      }
      if (k == jump_frame) ax.x_true(1) += 2.0;
      ax.x = F * ax.x;
      ax.P = F * ax.P * F.transpose() + s * s * Q;
      xm(a) = ax.x(1);
      z[a] = ax.x_true(0) + kSigmaMeas * n01(rng);
    }
    const auto chi2_of = [&](int a) {
      const double r = z[a] - axes[a].x(0);
      return r * r / (axes[a].P(0, 0) + kSigmaMeas * kSigmaMeas);
    };
    bool inflated = false;
    for (;;) {
      const double chi2 = chi2_of(0) + chi2_of(1) + chi2_of(2);
      if (!use.before_update || !est.inflate_before_update(chi2, 3, kDt)) break;
      inflated = true;
      for (Axis& ax : axes) add_inflation(est, &ax);
    }
    // One block of the three axes (the filter's blocks share the target's error).
    const bool accept = !use.gate || chi2_of(0) + chi2_of(1) + chi2_of(2) < 7.815;  // χ²_0.95(3)
    double nees = 0.0;
    for (int a = 0; a < 3; ++a) {
      Axis& ax = axes[a];
      Pm(a) = ax.P(1, 1);
      est.add_innovation(chi2_of(a), 1);
      if (accept) {
        const double S = ax.P(0, 0) + kSigmaMeas * kSigmaMeas;
        const Eigen::Vector2d K = ax.P.col(0) / S;
        ax.x += K * (z[a] - ax.x(0));
        ax.P = (Eigen::Matrix2d::Identity() - K * Eigen::RowVector2d(1.0, 0.0)) * ax.P;
      }
      xp(a) = ax.x(1);
      Pp(a) = ax.P(1, 1);
      const Eigen::Vector2d e = ax.x_true - ax.x;
      nees += e.dot(ax.P.ldlt().solve(e));
    }
    if (inflated) {
      est.end_frame_innovations_only(kDt);
    } else {
      est.end_frame(xm, Pm, xp, Pp, kDt);
    }
    if (use.inflate) {
      for (Axis& ax : axes) add_inflation(est, &ax);
    }
    out.position_error.push_back(std::sqrt(std::pow(axes[0].x_true(0) - axes[0].x(0), 2) +
                                           std::pow(axes[1].x_true(0) - axes[1].x(0), 2) +
                                           std::pow(axes[2].x_true(0) - axes[2].x(0), 2)));
    out.sigma.push_back(est.sigma());
    out.matched.push_back(est.matched_sigma());
    out.nees.push_back(nees);
    out.consistent.push_back(est.consistent());
  }
  out.violations = est.violations();
  return out;
}

double mean(const std::vector<double>& v, size_t from, size_t to) {
  double s = 0.0;
  for (size_t i = from; i < to; ++i) s += v[i];
  return s / static_cast<double>(to - from);
}

// √(mean σ̂²): the estimate is of σ², so its spread does not bias this down (Jensen).
double rms(const std::vector<double>& v, size_t from, size_t to) {
  double s = 0.0;
  for (size_t i = from; i < to; ++i) s += v[i] * v[i];
  return std::sqrt(s / static_cast<double>(to - from));
}

}  // namespace

TEST_CASE("adaptive noise: the estimate follows a step of the true density", "[adaptive]") {
  // 0.05 for 120 s, then 0.3 for 120 s; started far below and far above.
  // From above the matching converges slowly (≈ 50 s from 10× too large: the
  // position measurements dominate the velocity's corrections), so the
  // second minute of each phase is compared. Per frame (horizon 1) and with
  // the corrections summed over 10 frames: a right model's corrections are
  // uncorrelated, so the sum's square matches the same density
  // (adaptive_noise.h).
  const int half = 2400;
  const auto truth = [&](int k) { return k < half ? 0.05 : 0.3; };
  for (const int horizon : {1, 10}) {
    AdaptiveNoiseOptions options;
    options.horizon = horizon;
    for (const double sigma0 : {0.001, 0.5}) {
      for (uint64_t seed = 1; seed <= 3; ++seed) {
        const RunResult r = run(seed, 2 * half, sigma0, truth, -1, options);
        // Second half of each phase (the window is 2 s; 30 s to settle is ample).
        const double s1 = rms(r.sigma, half / 2, half);
        const double s2 = rms(r.sigma, half + half / 2, 2 * half);
        INFO("horizon " << horizon << " sigma0 " << sigma0 << " seed " << seed << ": " << s1 << " (true 0.05), "
                        << s2 << " (true 0.3)");
        // 20 %: one 2-s window scatters by ±40 % here, and under the feedback
        // (σ̂ sets the next gains) the low phase reads ≈ 12 % low at horizon 1
        // (measured 0.041–0.046 over seeds 1–5; docs/target_model.md).
        CHECK(std::abs(s1 / 0.05 - 1.0) < 0.2);
        CHECK(std::abs(s2 / 0.3 - 1.0) < 0.2);
      }
    }
  }
}

TEST_CASE("adaptive noise: the horizon squares the summed corrections, by hand", "[adaptive]") {
  // Frames whose covariance terms cancel (P⁻ − P⁺ = σ_used² dt), so a block's
  // sample is (Σ Δx)² per component and σ̂² = Σ blocks (Σ Δx)² / Σ blocks h dt.
  // Corrections of one sign every frame (a lag the model reads as noise):
  // h d² / dt, growing with h. Alternating signs (the overcorrection of a
  // gain too large): 0 for an even h, d² / dt for h = 1 that ignores the
  // correlation (Mehra's whiteness of a right model's innovations).
  const double d = 0.01;
  const auto matched = [&](int horizon, bool alternate) {
    AdaptiveNoiseOptions o;
    o.horizon = horizon;
    AdaptiveNoise est(o, 0.1);
    for (int k = 0; k < o.window; ++k) {
      const double dx = alternate && k % 2 ? -d : d;
      const double s2dt = est.sigma() * est.sigma() * kDt;
      est.end_frame(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(s2dt), Eigen::Vector3d::Constant(dx),
                    Eigen::Vector3d::Zero(), kDt);
    }
    return est.matched_sigma();
  };
  CHECK(matched(1, false) == Approx(std::sqrt(d * d / kDt)));
  CHECK(matched(10, false) == Approx(std::sqrt(10 * d * d / kDt)));
  CHECK(matched(1, true) == Approx(std::sqrt(d * d / kDt)));
  CHECK(matched(2, true) == AdaptiveNoiseOptions{}.sigma_min);  // (d − d)² = 0, clamped
}

TEST_CASE("adaptive noise: the hold keeps the largest recent estimate", "[adaptive]") {
  // 0.3 for 120 s, then 0.05 for 120 s, hold 20 s: after the step down the
  // σ used stays at the high phase's level through the hold. (It does not come
  // back down here within 100 s: from above the matching converges slowly and
  // the hold keeps its largest window; docs/target_model.md, "The hold".)
  AdaptiveNoiseOptions options;
  options.hold_s = 20.0;
  const int half = 2400;
  const int hold_frames = static_cast<int>(options.hold_s / kDt);
  const auto truth = [&](int k) { return k < half ? 0.3 : 0.05; };
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    const RunResult r = run(seed, 2 * half, 0.3, truth, -1, options);
    REQUIRE(r.violations == 0);
    // The definition: the largest windowed estimate of the last hold_s (to a
    // frame: the hold's edge is a sum of frame times).
    const auto largest_since = [&](int first, int k) {
      double largest = 0.0;
      for (int i = first; i <= k; ++i) largest = std::max(largest, r.matched[i]);
      return largest;
    };
    for (int k = options.window + hold_frames; k < 2 * half; ++k) {
      INFO("seed " << seed << " frame " << k);
      REQUIRE(r.sigma[k] >= largest_since(k - hold_frames + 1, k));
      REQUIRE(r.sigma[k] <= largest_since(k - hold_frames - 1, k));
    }
    const double held = *std::min_element(r.sigma.begin() + half + options.window, r.sigma.begin() + half + hold_frames);
    INFO("seed " << seed << ": smallest σ over the hold after the step down " << held << " (high phase 0.3)");
    CHECK(held > 0.2);
  }
}

TEST_CASE("adaptive noise: the adaptive filter is consistent (NEES)", "[adaptive]") {
  const auto truth = [](int k) { return k < 1200 ? 0.05 : 0.3; };
  double nees = 0.0;
  const int runs = 5;
  for (uint64_t seed = 11; seed < 11 + runs; ++seed) {
    const RunResult r = run(seed, 2400, 0.01, truth);
    nees += mean(r.nees, 200, r.nees.size()) / runs;  // after the first 10 s of adaptation
  }
  INFO("average NEES of [p, v] × 3 axes (6 dof): " << nees);
  // The project's band [1.5, 6] for 3 dof, i.e. [0.5, 2] per dof.
  CHECK(nees > 0.5 * 6);
  CHECK(nees < 2.0 * 6);
}

TEST_CASE("adaptive noise: the check flags a model violation, not a consistent run", "[adaptive]") {
  const auto constant = [](int) { return 0.1; };
  for (uint64_t seed = 21; seed <= 25; ++seed) {
    // Consistent: the filter starts at the true density.
    const RunResult ok = run(seed, 2400, 0.1, constant);
    CHECK(ok.violations == 0);
    int coupled = 0;
    for (bool c : ok.consistent) coupled += c ? 1 : 0;
    INFO("coupled frames " << coupled << " of 2400");
    CHECK(coupled >= 2400 - 40);  // all but the first window
    // A 2 m/s velocity jump at frame 1200: flagged, loosely coupled after it.
    const RunResult bad = run(seed, 3600, 0.1, constant, 1200);
    CHECK(bad.violations >= 1);
    CHECK(bad.consistent[1199]);
    bool dropped = false;
    for (int k = 1200; k < 1205; ++k) dropped = dropped || !bad.consistent[k];
    CHECK(dropped);
    // and back to tight coupling once the model fits again (σ̂ back down,
    // from above: slowly, so the third minute is compared).
    CHECK(bad.consistent.back());
    CHECK(std::abs(rms(bad.sigma, 2400, 3600) / 0.1 - 1.0) < 0.2);
  }
}

TEST_CASE("adaptive noise: a violating frame stepped before its update keeps the target", "[adaptive]") {
  // The filter's gate and the violation's inflation; the truth a random walk
  // of 0.001 that accelerates at 1 m/s² on every axis from 10 to 12 s (a car
  // speeding up), the filter started at the matching 0.001. Stepped after
  // the frame, the violating frames' measurements are gated out while σ is
  // bracketed frame by frame: the estimate drifts, and σ overshoots.
  // Stepped before the update, the frame's own measurement corrects it.
  Use after;
  after.gate = true;
  after.inflate = true;
  after.accel_from = 10.0;
  after.accel_to = 12.0;
  Use before = after;
  before.before_update = true;
  const auto truth = [](int) { return 0.001; };
  const size_t from = 200, to = 400;  // 10 to 20 s
  for (uint64_t seed = 31; seed <= 35; ++seed) {
    const RunResult a = run(seed, 600, 0.001, truth, -1, {}, after);
    const RunResult b = run(seed, 600, 0.001, truth, -1, {}, before);
    const double peak_a = *std::max_element(a.sigma.begin() + from, a.sigma.begin() + to);
    const double peak_b = *std::max_element(b.sigma.begin() + from, b.sigma.begin() + to);
    INFO("seed " << seed << ": position RMS 10-20 s " << rms(a.position_error, from, to) << " m after, "
                 << rms(b.position_error, from, to) << " m before the update; largest σ " << peak_a << ", "
                 << peak_b << "; violations " << a.violations << ", " << b.violations);
    // Measured, seeds 31–35: 0.013–0.050 m against 0.084–0.25 m; largest σ
    // 0.47–0.73 against the clamp, 2.
    CHECK(rms(b.position_error, from, to) < rms(a.position_error, from, to));
    CHECK(peak_a == AdaptiveNoiseOptions{}.sigma_max);
    CHECK(peak_b < peak_a);
  }
}

TEST_CASE("adaptive noise: the steps before an update, by hand", "[adaptive]") {
  AdaptiveNoiseOptions o;  // nis_max 2, max_step 4
  AdaptiveNoise est(o, 0.01);
  // χ²_0.99(10) = 23.21: 2× that is the violation bound, χ²_0.95(10) = 18.31 where stepping stops.
  CHECK_FALSE(est.inflate_before_update(40.0, 10, kDt));  // NIS 4 but below 46.4: no violation
  CHECK(est.inflation() == 0.0);
  CHECK(est.violations() == 0);
  REQUIRE(est.inflate_before_update(300.0, 10, kDt));  // NIS 30: the step is capped at σ² × 4
  CHECK(est.sigma() == Approx(0.02));
  CHECK(est.inflation_time() == Approx(kDt));  // no window yet: τ = this frame
  CHECK(est.inflation() == Approx((0.02 * 0.02 - 0.01 * 0.01) * kDt));
  CHECK_FALSE(est.consistent());
  // Once violated, on while above χ²_0.95(10), with σ² × NIS (< 4) and the same τ.
  REQUIRE(est.inflate_before_update(20.0, 10, kDt));
  CHECK(est.sigma() == Approx(0.02 * std::sqrt(2.0)));
  CHECK(est.inflation() == Approx((0.0008 - 0.0004) * kDt));
  CHECK_FALSE(est.inflate_before_update(18.0, 10, kDt));
  CHECK(est.violations() == 2);
  // The frame then ends consistent: no third violation, no inflation left.
  est.add_innovation(18.0, 10);
  est.end_frame_innovations_only(kDt);
  CHECK(est.violations() == 2);
  CHECK(est.inflation() == 0.0);
  // At the clamp there is no step to take.
  AdaptiveNoise top(o, o.sigma_max);
  CHECK_FALSE(top.inflate_before_update(1e6, 10, kDt));
}

TEST_CASE("adaptive noise: bad options are refused", "[adaptive]") {
  AdaptiveNoiseOptions o;
  o.window = 1;
  CHECK_THROWS_AS(AdaptiveNoise(o, 0.1), std::invalid_argument);
  o = AdaptiveNoiseOptions{};
  o.sigma_max = 0.5 * o.sigma_min;
  CHECK_THROWS_AS(AdaptiveNoise(o, 0.1), std::invalid_argument);
  o = AdaptiveNoiseOptions{};
  o.nis_max = 1.0;
  CHECK_THROWS_AS(AdaptiveNoise(o, 0.1), std::invalid_argument);
  o = AdaptiveNoiseOptions{};
  o.horizon = o.window + 1;
  CHECK_THROWS_AS(AdaptiveNoise(o, 0.1), std::invalid_argument);
  o.horizon = 0;
  CHECK_THROWS_AS(AdaptiveNoise(o, 0.1), std::invalid_argument);
  AdaptiveNoise est(AdaptiveNoiseOptions{}, 0.1);
  CHECK_THROWS_AS(est.end_frame(Eigen::VectorXd(3), Eigen::VectorXd(2), Eigen::VectorXd(3), Eigen::VectorXd(3), kDt),
                  std::invalid_argument);
  CHECK_THROWS_AS(est.end_frame(Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1), Eigen::VectorXd::Zero(1),
                                Eigen::VectorXd::Zero(1), 0.0),
                  std::invalid_argument);
  // The start is clamped into [sigma_min, sigma_max].
  CHECK(AdaptiveNoise(AdaptiveNoiseOptions{}, 0.0).sigma() == AdaptiveNoiseOptions{}.sigma_min);
}

// The joint robot + target filter (common/target/target_filter.h) on the
// simulator's paper scenario (UAV following a planar target), ~20 s,
// started from ground truth like tests/estimator/vio_sim_test.cc.
//  (a) Schmidt property: with SKF the robot estimate at every frame equals
//      the VIO-only estimate (no extension) for several σ_t and both
//      representations;
//  (b) the target is tracked (local SKF, σ_t = 0.05);
//  (c) EKF mode changes the robot estimate (tightly coupled).

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/vio_estimator.h"
#include "common/eval/initial_estimate.h"
#include "common/eval/vins_config.h"
#include "common/math/quat.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"
#include "common/target/target_filter.h"
#include "common/types/ground_truth.h"

using namespace vimot;
using namespace vimot::estimator;
using namespace vimot::target;

namespace {

constexpr uint64_t kSeed = 3;
constexpr double kDuration = 20.0;

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

VioOptions estimator_options() {
  VioOptions o = eval::load_vio_options(source_path("config/vins.yaml"));
  o.init_sigmas.theta_rp = 1e-3;
  o.init_sigmas.theta_yaw = 1e-3;
  o.init_sigmas.p = 1e-3;
  o.init_sigmas.v = 1e-3;
  o.init_sigmas.bg = 1e-4;
  o.init_sigmas.ba = 1e-3;
  return o;
}

struct Run {
  std::vector<Eigen::Matrix<double, 16, 1>> imu;  // IMU estimate after every processed frame
  bool diverged{false};
  bool target_initialized{false};
  TargetUpdateStats stats;
  Eigen::Vector3d p_TinI_err{Eigen::Vector3d::Zero()};  // final, estimate − truth
  Eigen::Matrix3d p_TinI_cov{Eigen::Matrix3d::Zero()};
  double max_nees_p{0.0};                               // over the last half of the run
  double rms_err_second_half{0.0};                      // |p_TinI err| RMS over the last half
};

// options == nullopt: VIO only (no extension attached).
Run run(const std::optional<TargetFilterOptions>& options) {
  sim::SimConfig cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  cfg.seed = kSeed;
  cfg.duration = kDuration;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);
  const VioOptions vo = estimator_options();
  VioEstimator est(vo);
  const eval::InitialEstimate x0 = eval::initial_estimate(sim.initial_state(), vo, eval::perturb_seed_for_run(kSeed));
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);
  std::unique_ptr<TargetFilter> filter;
  if (options) filter = std::make_unique<TargetFilter>(est, *options);

  Run out;
  GroundTruth truth;
  double sum_sq = 0.0;
  int n_second_half = 0;
  while (std::optional<sim::SimEvent> ev = sim.next()) {
    if (const auto* imu = std::get_if<ImuData>(&*ev)) {
      est.feed_imu(*imu);
      continue;
    }
    if (const auto* gt = std::get_if<GroundTruth>(&*ev)) {
      truth = *gt;
      if (filter) filter->set_ground_truth(*gt);
      continue;
    }
    const auto& frame = std::get<CameraFrame>(*ev);
    const FrameStatus s = est.feed_camera(frame);
    if (s == FrameStatus::kDiverged) {
      out.diverged = true;
      break;
    }
    if (s != FrameStatus::kProcessed) continue;
    out.imu.push_back(est.imu_value().to_vector());
    if (filter && filter->initialized() && truth.utime == frame.utime && truth.has_target) {
      Eigen::Matrix3d P;
      const Eigen::Vector3d p = filter->p_TinI(&P);
      const Eigen::Vector3d p_true = quat_to_rot(truth.q_GtoI) * (truth.p_TinG - truth.p_IinG);
      out.p_TinI_err = p - p_true;
      out.p_TinI_cov = P;
      if (frame.utime - sim.initial_state().utime > static_cast<int64_t>(0.5e6 * kDuration)) {
        out.max_nees_p = std::max(out.max_nees_p, out.p_TinI_err.dot(P.ldlt().solve(out.p_TinI_err)));
        sum_sq += out.p_TinI_err.squaredNorm();
        ++n_second_half;
      }
    }
  }
  if (n_second_half > 0) out.rms_err_second_half = std::sqrt(sum_sq / n_second_half);
  if (filter) {
    out.target_initialized = filter->initialized();
    out.stats = filter->stats();
  }
  return out;
}

double max_robot_difference(const Run& a, const Run& b) {
  REQUIRE(a.imu.size() == b.imu.size());
  double d = 0.0;
  for (size_t i = 0; i < a.imu.size(); ++i) {
    Eigen::Matrix<double, 16, 1> e = a.imu[i] - b.imu[i];
    // q and −q are the same rotation; the estimator keeps q_w >= 0 or not,
    // either way both runs use the same convention.
    d = std::max(d, e.cwiseAbs().maxCoeff());
  }
  return d;
}

TargetFilterOptions filter_options(TargetUpdateMode mode, TargetRepresentation rep, double sigma_t) {
  TargetFilterOptions o;
  o.mode = mode;
  o.representation = rep;
  o.sigma_t = sigma_t;
  o.planar = true;
  return o;
}

const Run& vio_only() {
  static const Run r = run(std::nullopt);
  return r;
}

}  // namespace

TEST_CASE("SKF target updates leave the robot estimate unchanged", "[target_filter]") {
  const Run& base = vio_only();
  REQUIRE_FALSE(base.diverged);
  REQUIRE(base.imu.size() > 150);
  for (const TargetRepresentation rep : {TargetRepresentation::kLocal, TargetRepresentation::kGlobal}) {
    for (const double sigma_t : {0.001, 0.05, 0.5}) {
      const Run r = run(filter_options(TargetUpdateMode::kSkf, rep, sigma_t));
      const double d = max_robot_difference(base, r);
      std::printf("SKF %s sigma_t %.3f: target updates %lld (tracks %lld, chi2 rej %lld, tri rej %lld), "
                  "max |robot SKF - VIO| %.3g, final |p_TinI err| %.4f m (3 sigma %.4f m)\n",
                  to_string(rep), sigma_t, static_cast<long long>(r.stats.updates),
                  static_cast<long long>(r.stats.tracks_used), static_cast<long long>(r.stats.rejected_chi2),
                  static_cast<long long>(r.stats.rejected_triangulation), d, r.p_TinI_err.norm(),
                  3.0 * std::sqrt(r.p_TinI_cov.trace()));
      CHECK_FALSE(r.diverged);
      CHECK(r.target_initialized);
      CHECK(r.stats.updates > 50);
      CHECK(d < 1e-9);
    }
  }
}

TEST_CASE("Local SKF tracks the target", "[target_filter]") {
  const Run r = run(filter_options(TargetUpdateMode::kSkf, TargetRepresentation::kLocal, 0.05));
  const Run off = run(filter_options(TargetUpdateMode::kOff, TargetRepresentation::kLocal, 0.05));
  const double sigma = std::sqrt(r.p_TinI_cov.trace());
  std::printf("local SKF: final p_TinI error [%.4f %.4f %.4f] |%.4f| m, sqrt(trace P) %.4f m, max NEES (2nd half) %.2f, RMS err (2nd half) %.4f m; "
              "prediction only: |%.3f| m, sqrt(trace P) %.3f m\n",
              r.p_TinI_err.x(), r.p_TinI_err.y(), r.p_TinI_err.z(), r.p_TinI_err.norm(), sigma, r.max_nees_p, r.rms_err_second_half,
              off.p_TinI_err.norm(), std::sqrt(off.p_TinI_cov.trace()));
  REQUIRE_FALSE(r.diverged);
  REQUIRE(r.stats.updates > 50);
  // Within 3σ of its own covariance (norm vs 3·sqrt(trace P)). The accuracy
  // target of the issue (paper: 0.00665 m) is not asserted yet: this first
  // integration reaches 0.08 m on seed 3, barely better than prediction
  // alone, which is under investigation (see the issue note).
  CHECK(r.p_TinI_err.norm() < 3.0 * sigma);
  // The updates carry information: far tighter than prediction alone.
  CHECK(sigma < 0.5 * std::sqrt(off.p_TinI_cov.trace()));
}

TEST_CASE("EKF target updates change the robot estimate", "[target_filter]") {
  const Run& base = vio_only();
  const Run r = run(filter_options(TargetUpdateMode::kEkf, TargetRepresentation::kGlobal, 0.05));
  const double d = max_robot_difference(base, r);
  std::printf("EKF global sigma_t 0.05: target updates %lld, max |robot EKF - VIO| %.3g, final |p_TinI err| %.4f m\n",
              static_cast<long long>(r.stats.updates), d, r.p_TinI_err.norm());
  REQUIRE_FALSE(r.diverged);
  REQUIRE(r.stats.updates > 50);
  CHECK(d > 1e-6);
}

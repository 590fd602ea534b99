// The target filter started from its own target features (init mode
// features, common/target/target_filter.h) on the simulator's paper
// scenario: the filter never sees the ground truth. The test uses the truth
// only to evaluate, through the fixed transform between the filter's target
// frame and the true one (common/eval/target_frame.h), as the evaluators do.

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/state_helper.h"
#include "common/estimator/vio_estimator.h"
#include "common/estimator/initial_estimate.h"
#include "common/eval/metrics.h"
#include "common/eval/target_frame.h"
#include "common/estimator/vins_config.h"
#include "common/math/quat.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"
#include "common/target/target_conversion.h"
#include "common/target/target_filter.h"
#include "common/target/target_filter_config.h"

using namespace vimot;
using namespace vimot::estimator;
using namespace vimot::target;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

struct Run {
  bool diverged{false};
  int64_t first_target_frame{-1};  // index of the first processed frame with target observations
  int64_t init_frame{-1};          // index of the frame the filter initialised at
  std::optional<TargetFeatureInitInfo> init;
  eval::TargetFrameTransform X;
  GroundTruth truth_at_init;
  Eigen::Matrix3d robot_theta_cov_at_init{Eigen::Matrix3d::Zero()};
  Eigen::Vector3d true_centroid_in_T{Eigen::Vector3d::Zero()};
  // Target in IMU after the fixed transform, every frame after initialisation.
  std::vector<eval::ErrorSample> samples;
  TargetUpdateStats stats;
};

// edit: applied to every camera frame (by its index) before the estimator sees it.
Run run(uint64_t seed, double duration, TargetRepresentation rep = TargetRepresentation::kLocal,
        const std::function<void(int64_t, CameraFrame&)>& edit = {}) {
  sim::SimConfig cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  cfg.seed = seed;
  cfg.duration = duration;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);
  const VioOptions vo = load_vio_options(source_path("config/vins.yaml"));
  VioEstimator est(vo);
  // The robot's own start (vins' simulation start: the perturbed truth); the
  // target filter gets no ground truth at all.
  const InitialEstimate x0 = initial_estimate(sim.initial_state(), vo, perturb_seed_for_run(seed));
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);
  // The shipped filter (its gauge prior, its points), started from features.
  TargetFilterOptions o = target_section_from_config(Config::load_file(source_path("config/target_filter.yaml"))).filter;
  o.mode = TargetUpdateMode::kSkf;
  o.init_mode = TargetInitMode::kFeatures;
  o.representation = rep;
  o.sigma_t = 0.05;
  TargetFilter filter(est, o);

  Run out;
  GroundTruth truth;
  int64_t frame = -1;
  int64_t frames_seen = 0;
  const bool trace = std::getenv("DIAG_TRACE") != nullptr;
  while (std::optional<sim::SimEvent> ev = sim.next()) {
    if (const auto* imu = std::get_if<ImuData>(&*ev)) {
      est.feed_imu(*imu);
      continue;
    }
    if (const auto* gt = std::get_if<GroundTruth>(&*ev)) {
      truth = *gt;
      continue;
    }
    auto& cam = std::get<CameraFrame>(*ev);
    if (edit) edit(frames_seen, cam);
    ++frames_seen;
    const bool was_initialized = filter.initialized();
    const FrameStatus s = est.feed_camera(cam);
    if (s == FrameStatus::kDiverged) {
      out.diverged = true;
      break;
    }
    if (s != FrameStatus::kProcessed) continue;
    ++frame;
    bool has_target = false;
    for (const auto& ob : cam.observations) has_target = has_target || ob.is_target;
    if (has_target && out.first_target_frame < 0) out.first_target_frame = frame;
    if (!filter.initialized() || truth.utime != cam.utime || !truth.has_target) continue;
    const State& st = est.state();
    const PoseValue ip = imu_pose(est.imu_value());
    const Eigen::Matrix<double, 18, 18> P18 =
        StateHelper::marginal_covariance(st, {st.imu()->pose()->q(), st.imu()->pose()->p(), filter.target()});
    TargetValue x_i = filter.value();
    Matrix12d P_i = P18.block<12, 12>(6, 6);
    if (rep == TargetRepresentation::kGlobal) {
      x_i = global_to_local(ip, filter.value());
      P_i = global_to_local_covariance(ip, filter.value(), P18);
    }
    if (!was_initialized) {
      out.init_frame = frame;
      out.init = filter.feature_init_info();
      out.X = eval::target_frame_transform(truth, x_i.q_RtoT, x_i.p_TinR);
      out.truth_at_init = truth;
      out.robot_theta_cov_at_init = P18.block<3, 3>(0, 0);
    }
    const GroundTruth t = eval::in_target_frame(truth, out.X);
    const eval::TargetInImu ti = eval::true_target_in_imu(t);
    out.samples.push_back(eval::compute_error(cam.utime, ti.q_ItoT, ti.p_TinI, x_i.q_RtoT, x_i.p_TinR,
                                              P_i.block<3, 3>(0, 0), P_i.block<3, 3>(3, 3)));
    if (trace && frame % 10 == 0) {
      const eval::ErrorSample& e = out.samples.back();
      std::printf("  f %lld err p [%.3f %.3f %.3f] th(deg) [%.2f %.2f %.2f] nees %.2f/%.2f v [%.2f %.2f %.2f] true "
                  "[%.2f %.2f %.2f] w %.3f true %.3f pts %zu\n",
                  static_cast<long long>(frame), e.err_p.x(), e.err_p.y(), e.err_p.z(), e.err_theta.x() * 57.3,
                  e.err_theta.y() * 57.3, e.err_theta.z() * 57.3, e.nees_p, e.nees_theta, x_i.v_TinT.x(),
                  x_i.v_TinT.y(), x_i.v_TinT.z(), t.v_TinT.x(), t.v_TinT.y(), t.v_TinT.z(), x_i.w_TinT.z(),
                  t.w_TinT.z(), filter.points().size());
    }
  }
  out.stats = filter.stats();
  if (out.init) {
    // The true centroid, in T, of the body points the filter put its origin at.
    for (const int64_t id : out.init->feature_ids) {
      out.true_centroid_in_T += sim.landmarks().at(static_cast<size_t>(sim.landmark_of_feature(id))).p;
    }
    out.true_centroid_in_T /= static_cast<double>(out.init->feature_ids.size());
  }
  return out;
}

}  // namespace

TEST_CASE("features start: no ground truth, started within its window, tracked consistently", "[target_filter]") {
  const TargetFeatureInit defaults;
  // Per run: mean NEES of the target-in-IMU position and orientation.
  std::vector<double> nees_p, nees_theta;
  for (const uint64_t seed : {1, 2, 3, 4}) {
    const Run r = run(seed, 20.0);
    eval::TrajectoryErrors e;
    for (const auto& s : r.samples) e.add(s);
    const eval::ErrorSummary sum = e.summary();
    INFO("seed " << seed << ": init frame " << r.init_frame << " (target from " << r.first_target_frame << "), X "
                 << r.X.describe() << ", RMSE " << sum.rmse_position_m << " m (predicted "
                 << sum.predicted_rmse_position_m << ") " << sum.rmse_orientation_deg << " deg (predicted "
                 << sum.predicted_rmse_orientation_deg << "), NEES " << sum.nees_position << " / "
                 << sum.nees_orientation);
    REQUIRE_FALSE(r.diverged);
    REQUIRE(r.init);
    REQUIRE(r.first_target_frame >= 0);
    // The paper scenario keeps the target in view with ~40 stereo target
    // features a frame, far above min_points, so the start takes exactly its
    // window of consecutive frames.
    CHECK(r.init_frame - r.first_target_frame == defaults.frames - 1);
    CHECK(static_cast<int>(r.init->feature_ids.size()) >= defaults.min_points);

    // The reported transform is what the start prescribes: the filter's axes
    // are those of its G (X ≈ R_TtoG, off by the robot's orientation error),
    // its origin the centroid of those features (off by their triangulation
    // error).
    const Eigen::Vector4d q_TtoG = quat_inverse(r.truth_at_init.q_GtoT);
    CHECK(eval::orientation_error(r.X.q_TtoTest, q_TtoG).norm() < 3.0 * std::sqrt(r.robot_theta_cov_at_init.trace()));
    CHECK((r.X.p_TestInT - r.true_centroid_in_T).norm() < 3.0 * std::sqrt(r.init->centroid_cov.trace()));

    // Tracked over the run: the RMSE within 3× what the filter's covariance
    // predicts, and the last error inside 3σ on every axis.
    REQUIRE(r.samples.size() > 150);
    CHECK(sum.rmse_position_m < 3.0 * sum.predicted_rmse_position_m);
    CHECK(sum.rmse_orientation_deg < 3.0 * sum.predicted_rmse_orientation_deg);
    const eval::ErrorSample& last = r.samples.back();
    for (int k = 0; k < 3; ++k) CHECK(std::abs(last.err_p(k)) < last.sig3_p(k));
    CHECK(r.stats.points_initialized > 0);
    nees_p.push_back(sum.nees_position);
    nees_theta.push_back(sum.nees_orientation);
  }
  // Consistent: the mean over the 4 runs of the run-averaged NEES (3 dof)
  // inside the two-sided 95 % band of χ²(12)/4, [4.40/4, 23.34/4], as if each
  // run gave one χ²(3) draw (a time average spreads less, so this is the
  // looser band). Before the points were re-linearised with their covariance
  // carried along the gauge, and with the code's 0.01 gauge prior instead of
  // the shipped 0.001, the position read 0.93 (conservative) and the
  // orientation 2.44; measured now 2.06 / 2.26 (docs/target_model.md).
  double mp = 0.0, mt = 0.0;
  for (std::size_t i = 0; i < nees_p.size(); ++i) {
    mp += nees_p[i] / static_cast<double>(nees_p.size());
    mt += nees_theta[i] / static_cast<double>(nees_theta.size());
  }
  INFO("mean NEES position " << mp << ", orientation " << mt);
  CHECK(mp > 4.40 / 4.0);
  CHECK(mp < 23.34 / 4.0);
  CHECK(mt > 4.40 / 4.0);
  CHECK(mt < 23.34 / 4.0);
}

TEST_CASE("features start: a frame without target features restarts the window", "[target_filter]") {
  const TargetFeatureInit defaults;
  const Run r = run(1, 3.0, TargetRepresentation::kLocal, [](int64_t i, CameraFrame& f) {
    if (i != 2) return;
    auto& obs = f.observations;
    obs.erase(std::remove_if(obs.begin(), obs.end(), [](const FeatureObservation& o) { return o.is_target; }),
              obs.end());
  });
  REQUIRE_FALSE(r.diverged);
  REQUIRE(r.first_target_frame == 0);
  REQUIRE(r.init);
  // Frames 0–1 are lost with the gap at 2; the window is frames 3 to 3 + frames − 1.
  CHECK(r.init_frame == 3 + defaults.frames - 1);
}

TEST_CASE("features start: global representation, correlated with the robot", "[target_filter]") {
  const Run r = run(1, 10.0, TargetRepresentation::kGlobal);
  REQUIRE_FALSE(r.diverged);
  REQUIRE(r.init);
  REQUIRE(r.samples.size() > 50);
  eval::TrajectoryErrors e;
  for (const auto& s : r.samples) e.add(s);
  const eval::ErrorSummary sum = e.summary();
  INFO("RMSE " << sum.rmse_position_m << " m (predicted " << sum.predicted_rmse_position_m << "), NEES "
               << sum.nees_position << " / " << sum.nees_orientation);
  // Target-in-IMU through the global state and the robot's covariance: the
  // first sample's error is zero by the transform's construction, and its
  // covariance is the gauge prior only if the cross-covariance with the
  // robot cancels the robot's part (δx_L = δx_G − J δx_I).
  const TargetFilterOptions defaults;
  const eval::ErrorSample& first = r.samples.front();
  CHECK(first.err_p.norm() < 1e-9);
  CHECK(first.sig3_p.maxCoeff() < 3.0 * defaults.init_sigmas.p * (1.0 + 1e-6));
  CHECK(first.sig3_theta.maxCoeff() < 3.0 * defaults.init_sigmas.theta * (1.0 + 1e-6));
  CHECK(sum.rmse_position_m < 3.0 * sum.predicted_rmse_position_m);
  const eval::ErrorSample& last = r.samples.back();
  for (int k = 0; k < 3; ++k) CHECK(std::abs(last.err_p(k)) < last.sig3_p(k));
}

TEST_CASE("features start: diagnostics", "[.diag]") {
  const char* env_seeds = std::getenv("DIAG_SEEDS");
  const int nseeds = env_seeds ? std::atoi(env_seeds) : 1;
  const TargetRepresentation rep = std::getenv("DIAG_GLOBAL") ? TargetRepresentation::kGlobal
                                                              : TargetRepresentation::kLocal;
  for (int i = 0; i < nseeds; ++i) {
    const Run r = run(3 + static_cast<uint64_t>(i), 20.0, rep);
    eval::TrajectoryErrors e;
    for (const auto& s : r.samples) e.add(s);
    const eval::ErrorSummary sum = e.summary();
    std::printf("seed %d: init frame %lld (target from %lld), %zu points, X %s | RMSE %.4f m %.3f deg NEES %.2f / %.2f\n",
                3 + i, static_cast<long long>(r.init_frame), static_cast<long long>(r.first_target_frame),
                r.init ? r.init->feature_ids.size() : 0, r.X.describe().c_str(), sum.rmse_position_m,
                sum.rmse_orientation_deg, sum.nees_position, sum.nees_orientation);
  }
}

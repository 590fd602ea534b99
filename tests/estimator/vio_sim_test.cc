// End-to-end: the estimator on the simulator's paper scenario (UAV following
// a target, 200 Hz ADIS16448 IMU, 10 Hz EuRoC stereo, 1 px noise), started
// from ground truth. Accuracy (position RMSE) and consistency (NEES of the
// IMU position and orientation) over a few seeds; determinism.

#include <catch2/catch.hpp>

#include <cstdio>
#include <map>
#include <numeric>
#include <random>

#include "common/config/config.h"
#include "common/estimator/vio_estimator.h"
#include "common/math/quat.h"
#include "common/sim/simulator.h"
#include "common/types/ground_truth.h"
#include "common/types/sensor_data.h"

using namespace vimot;
using namespace vimot::estimator;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

sim::SimConfig paper_config(uint64_t seed, double duration) {
  sim::SimConfig cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  cfg.seed = seed;
  cfg.duration = duration;
  return cfg;
}

VioOptions estimator_options(const sim::Simulator& s) {
  // Defaults of the estimator with the simulator's calibration.
  VioOptions o = VioOptions::from_config(Config::load_file(source_path("config/euroc_stereo.yaml")));
  o.cameras = s.cameras();
  o.sigma_px = s.config().camera.pixel_noise;
  const sim::ImuSimConfig& imu = s.imu_config();
  o.propagator.noise.sigma_w = imu.gyroscope_noise_density;
  o.propagator.noise.sigma_a = imu.accelerometer_noise_density;
  o.propagator.noise.sigma_wb = imu.gyroscope_random_walk;
  o.propagator.noise.sigma_ab = imu.accelerometer_random_walk;
  o.propagator.gravity_magnitude = imu.gravity;
  return o;
}

struct RunResult {
  double rmse_p{0.0};
  double rmse_theta_deg{0.0};
  double nees_p{0.0};
  double nees_theta{0.0};
  double mean_ms{0.0};
  double max_ms{0.0};
  double path_m{0.0};
  int frames{0};
  UpdateStats totals;
  std::vector<double> trace;  // final estimate, for determinism
  bool diverged{false};
  int64_t target_ignored{0};
};

RunResult run(uint64_t seed, double duration, const std::function<void(VioOptions&)>& tweak = nullptr) {
  sim::Simulator s(paper_config(seed, duration));
  VioOptions opt = estimator_options(s);
  if (tweak) tweak(opt);
  VioEstimator est(opt);
  const GroundTruth gt0 = s.initial_state();
  ImuValue x0;
  x0.q_GtoI = gt0.q_GtoI;
  x0.p_IinG = gt0.p_IinG;
  x0.v_IinG = gt0.v_IinG;
  x0.bg = gt0.bias_gyro;
  x0.ba = gt0.bias_accel;
  Matrix15d P0 = Matrix15d::Zero();
  P0.diagonal() << Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(1e-6),
      Eigen::Vector3d::Constant(1e-6), Eigen::Vector3d::Constant(1e-8), Eigen::Vector3d::Constant(1e-6);
  // Monte-Carlo NEES needs x̂0 − x0 ~ N(0, P0): start from truth ⊞ a sample
  // of P0 (starting exactly at truth with P0 > 0 makes NEES read low, since
  // the unobservable yaw/position keep their prior variance).
  std::mt19937 rng(1000 + seed);
  std::normal_distribution<double> n01;
  Eigen::Matrix<double, 15, 1> d;
  for (int i = 0; i < 15; ++i) d(i) = std::sqrt(P0(i, i)) * n01(rng);
  x0.q_GtoI = quat_boxplus(x0.q_GtoI, d.segment<3>(0));
  x0.p_IinG += d.segment<3>(3);
  x0.v_IinG += d.segment<3>(6);
  x0.bg += d.segment<3>(9);
  x0.ba += d.segment<3>(12);
  est.initialize(x0, gt0.utime, P0);

  std::map<int64_t, GroundTruth> truth;
  RunResult r;
  double se_p = 0.0, se_t = 0.0, nees_p = 0.0, nees_t = 0.0, ms = 0.0;
  int n_err = 0;
  s.run([&](const sim::SimEvent& ev) {
    if (const auto* imu = std::get_if<ImuData>(&ev)) {
      est.feed_imu(*imu);
    } else if (const auto* gt = std::get_if<GroundTruth>(&ev)) {
      truth[gt->utime] = *gt;
    } else if (const auto* cam = std::get_if<CameraFrame>(&ev)) {
      const FrameStatus st = est.feed_camera(*cam);
      if (st != FrameStatus::kProcessed) {
        r.diverged = r.diverged || st == FrameStatus::kDiverged;
        return;
      }
      ++r.frames;
      ms += est.last_timing().total_cpu_ms;
      r.max_ms = std::max(r.max_ms, est.last_timing().total_cpu_ms);
      const auto it = truth.find(cam->utime);
      if (it == truth.end()) return;
      const ImuValue x = est.imu_value();
      const Matrix15d P = est.imu_covariance();
      const Eigen::Vector3d e_p = it->second.p_IinG - x.p_IinG;
      // R_true = Exp(−δθ) R̂  →  δθ = −log(R_true R̂ᵀ).
      const Eigen::Vector3d e_t =
          -log_so3(quat_to_rot(it->second.q_GtoI) * quat_to_rot(x.q_GtoI).transpose());
      se_p += e_p.squaredNorm();
      se_t += e_t.squaredNorm();
      nees_p += e_p.dot(P.block<3, 3>(3, 3).ldlt().solve(e_p));
      nees_t += e_t.dot(P.block<3, 3>(0, 0).ldlt().solve(e_t));
      ++n_err;
    }
  });
  r.rmse_p = std::sqrt(se_p / n_err);
  r.rmse_theta_deg = std::sqrt(se_t / n_err) * 180.0 / M_PI;
  r.nees_p = nees_p / n_err;
  r.nees_theta = nees_t / n_err;
  r.mean_ms = ms / std::max(1, r.frames);
  r.path_m = s.path_length();
  r.totals = est.total_stats();
  r.target_ignored = est.target_observations_ignored();
  const auto v = est.imu_value().to_vector();
  r.trace.assign(v.data(), v.data() + v.size());
  const auto& C = est.state().cov();
  r.trace.insert(r.trace.end(), C.data(), C.data() + C.size());
  std::printf("seed %llu: %d frames, path %.1f m, RMSE %.3f m / %.3f deg, NEES pos %.2f ori %.2f, "
              "%.2f ms/frame CPU (max %.2f), MSCKF used %d (chi2 rej %d, tri rej %d, short %d, over max %d), "
              "SLAM init %d upd %d chi2 rej %d\n",
              static_cast<unsigned long long>(seed), r.frames, r.path_m, r.rmse_p, r.rmse_theta_deg, r.nees_p,
              r.nees_theta, r.mean_ms, r.max_ms, r.totals.msckf_used, r.totals.msckf_rejected_chi2,
              r.totals.msckf_rejected_triangulation, r.totals.msckf_rejected_short, r.totals.msckf_dropped_over_max, r.totals.slam_initialized,
              r.totals.slam_updated, r.totals.slam_rejected_chi2);
  return r;
}

}  // namespace

TEST_CASE("Paper scenario from ground truth: accurate and consistent", "[vio][sim]") {
  const double duration = 25.0;
  std::vector<RunResult> runs;
  for (uint64_t seed : {1, 2, 3, 4, 5, 6, 7, 8}) {
    runs.push_back(run(seed, duration));
    const RunResult& r = runs.back();
    CHECK_FALSE(r.diverged);
    CHECK(r.frames >= 240);
    // The paper's stand-alone VIO: 0.231 m RMSE over 165 m; 25 s is ~40 m.
    CHECK(r.rmse_p < 0.1);
    CHECK(r.target_ignored > 0);  // the target's points are left to the target filter
  }
  double nees_p = 0.0, nees_t = 0.0;
  for (const auto& r : runs) {
    nees_p += r.nees_p / runs.size();
    nees_t += r.nees_theta / runs.size();
  }
  std::printf("average NEES over seeds: position %.2f, orientation %.2f (ideal 3)\n", nees_p, nees_t);
  CHECK(nees_p > 1.5);
  CHECK(nees_p < 6.0);
  CHECK(nees_t > 1.5);
  CHECK(nees_t < 6.0);
}

TEST_CASE("Same input, bit-identical output", "[vio][sim]") {
  const RunResult a = run(7, 4.0);
  const RunResult b = run(7, 4.0);
  REQUIRE(a.trace.size() == b.trace.size());
  CHECK(a.trace == b.trace);
}

TEST_CASE("Anchored inverse-depth SLAM features", "[vio][sim]") {
  double nees_p = 0.0, nees_t = 0.0;
  for (uint64_t seed : {4, 5}) {
    const RunResult r = run(seed, 20.0, [](VioOptions& o) {
      o.state.slam_representation = LandmarkRepresentation::kAnchoredInverseDepth;
    });
    CHECK_FALSE(r.diverged);
    CHECK(r.rmse_p < 0.1);
    CHECK(r.totals.slam_initialized > 0);
    nees_p += r.nees_p / 2.0;
    nees_t += r.nees_theta / 2.0;
  }
  CHECK(nees_p < 6.0);
  CHECK(nees_t < 6.0);
}

TEST_CASE("Divergence is reported once and reset recovers", "[vio][sim]") {
  sim::Simulator s(paper_config(1, 3.0));
  VioOptions opt = estimator_options(s);
  opt.divergence.max_position_correction_m = 1e-9;  // any correction "diverges"
  VioEstimator est(opt);
  int reports = 0;
  std::string reason;
  est.set_divergence_callback([&](const DivergenceReport& d) {
    ++reports;
    reason = d.reason;
  });
  const GroundTruth gt0 = s.initial_state();
  ImuValue x0;
  x0.q_GtoI = gt0.q_GtoI;
  x0.p_IinG = gt0.p_IinG;
  x0.v_IinG = gt0.v_IinG;
  est.initialize(x0, gt0.utime);
  int diverged_frames = 0, processed_after_reset = 0;
  bool was_reset = false;
  s.run([&](const sim::SimEvent& ev) {
    if (const auto* imu = std::get_if<ImuData>(&ev)) {
      est.feed_imu(*imu);
    } else if (const auto* gt = std::get_if<GroundTruth>(&ev)) {
      if (est.diverged() && !was_reset && diverged_frames >= 2) {
        est.reset();
        CHECK_FALSE(est.initialized());
        ImuValue x;
        x.q_GtoI = gt->q_GtoI;
        x.p_IinG = gt->p_IinG;
        x.v_IinG = gt->v_IinG;
        est.initialize(x, gt->utime);
        was_reset = true;
      }
    } else if (const auto* cam = std::get_if<CameraFrame>(&ev)) {
      const FrameStatus st = est.feed_camera(*cam);
      if (st == FrameStatus::kDiverged) ++diverged_frames;
      if (was_reset && st != FrameStatus::kRejectedOutOfOrder) ++processed_after_reset;
    }
  });
  CHECK(reports >= 1);
  CHECK_THAT(reason, Catch::Contains("position correction"));
  CHECK(diverged_frames >= 2);
  CHECK(was_reset);
  CHECK(processed_after_reset > 0);
}

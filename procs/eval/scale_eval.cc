#include "procs/eval/scale_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <variant>

#include "common/eval/initial_estimate.h"
#include "common/eval/nav_state_of.h"
#include "common/math/quat.h"
#include "common/sim/simulator.h"
#include "procs/eval/object_truth.h"

namespace vimot {
namespace eval {

namespace {

// Z-Y-X (yaw about z, then pitch about y, then roll about x) angles of R.
Eigen::Vector3d yaw_pitch_roll(const Eigen::Matrix3d& R) {
  return Eigen::Vector3d(std::atan2(R(1, 0), R(0, 0)), -std::asin(std::clamp(R(2, 0), -1.0, 1.0)),
                         std::atan2(R(2, 1), R(2, 2)));
}

}  // namespace

MeanStd3 mean_std3(const std::vector<Eigen::Vector3d>& values) {
  MeanStd3 r;
  if (values.empty()) return r;
  for (const auto& v : values) r.mean += v;
  r.mean /= static_cast<double>(values.size());
  if (values.size() < 2) return r;
  Eigen::Vector3d sq = Eigen::Vector3d::Zero();
  for (const auto& v : values) sq += (v - r.mean).cwiseAbs2();
  r.std = (sq / static_cast<double>(values.size() - 1)).cwiseSqrt();
  return r;
}

AbsStats abs_stats(const std::vector<double>& errors) {
  AbsStats s;
  if (errors.empty()) return s;
  std::vector<double> a;
  for (double e : errors) a.push_back(std::abs(e));
  std::sort(a.begin(), a.end());
  s.median = a.size() % 2 == 1 ? a[a.size() / 2] : 0.5 * (a[a.size() / 2 - 1] + a[a.size() / 2]);
  s.max = a.back();
  return s;
}

ScaleRunResult run_scale_on_sim(const sim::SimConfig& sim_config, const ScaleEvalOptions& options,
                                uint64_t perturb_seed, const std::function<void(double)>& progress) {
  const auto wall_start = std::chrono::steady_clock::now();
  sim::SimConfig cfg = sim_config;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);
  if (!sim.has_target()) throw std::invalid_argument("run_scale_on_sim: the scenario has no target");
  ScaleRunResult r;
  r.sim_seed = cfg.seed;
  r.perturb_seed = perturb_seed;

  estimator::VioEstimator est(options.vio);
  const InitialEstimate x0 = initial_estimate(sim.initial_state(), options.vio, perturb_seed);
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);
  ObjectTracker tracker(options.tracker);

  // Truth of each track, keyed by track id (the tracker re-initialises).
  std::map<int64_t, ObjectTruth> truths;
  std::vector<double> scale_true_of_estimate;
  std::vector<Eigen::Vector3d> err_p, err_ypr;
  int64_t current_track = 0;
  std::optional<double> held_scale_error;
  ScaleNode node(
      options.node,
      [&](const scale::ScaleResult& s) {
        ++r.estimates;
        const auto it = truths.find(current_track);
        if (!s.accepted || it == truths.end()) return;
        ++r.accepted;
        r.accepted_scale_errors.push_back(s.scale / it->second.s_true - 1.0);
        held_scale_error = r.accepted_scale_errors.back();
      },
      [&](const scale::ObjectPoseInWorld& pose) {
        const auto it = truths.find(current_track);
        if (it == truths.end()) return;
        const ObjectTruth& truth = it->second;
        const sim::SplineState target = sim.target_state(sim.sim_time(pose.utime)).value();
        const Eigen::Matrix3d R_OtoG_true = target.R_BtoG * truth.R_OtoT;
        const Eigen::Vector3d p_OinG_true = target.R_BtoG * truth.p_OinT + target.p_BinG;
        MetricPoseSample m;
        m.utime = pose.utime;
        m.scale = pose.scale;
        m.scale_true = truth.s_true;
        m.err_p = pose.p_OinG - p_OinG_true;
        m.err_ypr = yaw_pitch_roll(pose.R_OtoG * R_OtoG_true.transpose());
        r.metric_poses.push_back(m);
        err_p.push_back(m.err_p);
        err_ypr.push_back(m.err_ypr);
      },
      {});

  TrajectoryErrors vio_errors;
  GroundTruth truth;
  bool have_truth = false;
  double tracker_s = 0.0;
  const int64_t frames_total = std::max<int64_t>(1, sim.camera_frame_count());
  while (std::optional<sim::SimEvent> ev = sim.next()) {
    if (const auto* imu = std::get_if<ImuData>(&*ev)) {
      est.feed_imu(*imu);
      continue;
    }
    if (const auto* gt = std::get_if<GroundTruth>(&*ev)) {
      truth = *gt;
      have_truth = true;
      continue;
    }
    const auto& frame = std::get<CameraFrame>(*ev);
    ++r.frames;
    if (progress) progress(static_cast<double>(r.frames) / static_cast<double>(frames_total));
    const estimator::FrameStatus st = est.feed_camera(frame);  // it leaves the target's observations out
    if (st == estimator::FrameStatus::kDiverged) {
      r.vio_diverged = true;
      r.divergence_reason = est.last_divergence().reason;
      break;
    }
    const auto t0 = std::chrono::steady_clock::now();
    const ObjectPoseEstimate pose = tracker.process(frame);
    tracker_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (pose.valid) {
      ++r.tracker_valid_frames;
      if (truths.count(pose.track_id) == 0 && tracker.init_facts()) {
        truths[pose.track_id] = object_truth(sim, *tracker.init_facts());
        ++r.tracks;
      }
      current_track = pose.track_id;
    }
    if (st != estimator::FrameStatus::kProcessed) continue;
    const NavState nav = nav_state_of(est, true);
    if (have_truth && truth.utime == frame.utime) vio_errors.add(error_of(nav, truth));
    node.on_nav_state(nav);
    node.on_object_pose(pose);
  }
  if (progress) progress(1.0);
  r.vio = vio_errors.summary();
  r.position_error = mean_std3(err_p);
  r.orientation_error = mean_std3(err_ypr);
  r.final_scale_error = held_scale_error.value_or(std::numeric_limits<double>::quiet_NaN());
  r.tracker_ms_mean = r.frames > 0 ? 1e3 * tracker_s / static_cast<double>(r.frames) : 0.0;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return r;
}

}  // namespace eval
}  // namespace vimot

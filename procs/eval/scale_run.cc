#include "procs/eval/scale_run.h"

#include <algorithm>
#include <chrono>
#include <deque>
#include <stdexcept>

#include "common/estimator/initial_estimate.h"
#include "common/estimator/nav_state_of.h"
#include "common/eval/sim_runner.h"
#include "common/eval/pixel_frontend.h"
#include "common/sim/simulator.h"
#include "procs/object_tracker/object_tracker_node.h"

namespace vimot {
namespace eval {

namespace {

// Frames kept for object_truth_from_pixels: the reference frame is the first of the
// object tracker's initialisation buffer (init_frames, 40 by default), which
// may slide on for a while before the tracker commits.
constexpr std::size_t kRecentFrames = 400;

const CameraFrame& reference_frame(const std::deque<CameraFrame>& recent, const InitFacts& facts) {
  const auto frame = std::find_if(recent.begin(), recent.end(),
                                  [&facts](const CameraFrame& f) { return f.utime == facts.reference_utime; });
  if (frame == recent.end()) throw std::runtime_error("object truth: the reference frame is no longer kept");
  return *frame;
}

}  // namespace

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
  std::optional<PixelFrontEnd> pixels;
  if (options.pixels) pixels.emplace(sim, *options.pixels, options.box_chain);
  const estimator::InitialEstimate x0 = estimator::initial_estimate(sim.initial_state(), options.vio, perturb_seed);
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);
  // The tracker's pose of the current frame (the node publishes one per
  // accepted frame; the simulator's utimes always increase).
  ObjectPoseEstimate tracked;
  ObjectTrackerNode tracker(options.tracker, [&tracked](const ObjectPoseEstimate& p) { tracked = p; }, {});
  ScaleFigureBuilder figures;
  auto true_target = [&sim](int64_t utime) { return sim.target_state(sim.sim_time(utime)).value(); };
  double held_scale = 0.0;  // of the metric pose the filter gets next, same frame
  // ScaleNode calls on_pose, then runs the object filter (update, outputs,
  // prediction), then on_object_state: the time between the two is the filter's.
  std::chrono::steady_clock::time_point pose_done;
  double filter_s = 0.0;
  int64_t filter_calls = 0;
  ScaleNode node(
      options.node, [&](const scale::ScaleResult& s) { figures.add_estimate(s.utime, s.scale, s.accepted); },
      [&](const scale::ObjectPoseInWorld& pose) {
        held_scale = pose.scale;
        const sim::SplineState target = true_target(pose.utime);
        figures.add_metric_pose(pose.utime, pose.scale, pose.R_OtoG, pose.p_OinG, target.R_BtoG, target.p_BinG);
        pose_done = std::chrono::steady_clock::now();
      },
      {},
      [&](const TargetStateEstimate& state, const TargetPosePrediction&) {
        filter_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - pose_done).count();
        ++filter_calls;
        const sim::SplineState target = true_target(state.utime);
        figures.add_filtered_pose(state, held_scale, target.R_BtoG, target.p_BinG);
      });

  TrajectoryErrors vio_errors;
  GroundTruth truth;
  bool have_truth = false;
  double tracker_s = 0.0;
  const int64_t frames_total = std::max<int64_t>(1, sim.camera_frame_count());
  auto on_truth = [&](const GroundTruth& gt) {
    truth = gt;
    have_truth = true;
  };
  std::deque<CameraFrame> recent_frames;  // from pixels: the reference frame's pixels give the true distances
  play_simulator(sim, est, on_truth, [&](const CameraFrame& frame) {
    ++r.frames;
    if (pixels) {
      recent_frames.push_back(frame);
      if (recent_frames.size() > kRecentFrames) recent_frames.pop_front();
    }
    if (progress) progress(static_cast<double>(r.frames) / static_cast<double>(frames_total));
    const estimator::FrameStatus st = est.feed_camera(frame);  // it leaves the target's observations out
    if (st == estimator::FrameStatus::kDiverged) {
      r.vio_diverged = true;
      r.divergence_reason = est.last_divergence().reason;
      return false;
    }
    if (pixels && !pixels->last_views().empty() && pixels->last_views()[0].visible) {
      // TARGET_BOX_TRUTH, as vimot-sim --render publishes it with the image.
      const Eigen::Vector4d& b = pixels->last_views()[0].box;
      tracker.on_box(frame.utime, BoundingBox2d{b.head<2>(), b.head<2>() + b.tail<2>()});
    }
    const auto t0 = std::chrono::steady_clock::now();
    tracker.on_frame(frame);
    tracker_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (tracked.valid) {
      ++r.tracker_valid_frames;
      if ((r.tracks.empty() || r.tracks.back().track_id != tracked.track_id) && tracker.tracker().init_facts()) {
        const InitFacts& facts = *tracker.tracker().init_facts();
        TrackTruth t{tracked.track_id, tracked.utime,
                     pixels ? object_truth_from_pixels(sim, pixels->renderer(), facts, reference_frame(recent_frames, facts))
                            : object_truth(sim, facts)};
        figures.start_track(t.start_utime, t.truth);
        r.tracks.push_back(t);
      }
    }
    if (st != estimator::FrameStatus::kProcessed) return true;
    const NavState nav = estimator::nav_state_of(est, true);
    if (have_truth && truth.utime == frame.utime) vio_errors.add(error_of(nav, truth));
    node.on_nav_state(nav);
    node.on_object_pose(tracked);
    return true;
  }, pixels ? &*pixels : nullptr);
  if (progress) progress(1.0);
  r.vio = vio_errors.summary();
  r.figures = figures.figures();
  r.tracker_ms_mean = r.frames > 0 ? 1e3 * tracker_s / static_cast<double>(r.frames) : 0.0;
  r.filter_us_mean = filter_calls > 0 ? 1e6 * filter_s / static_cast<double>(filter_calls) : 0.0;
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return r;
}

}  // namespace eval
}  // namespace vimot

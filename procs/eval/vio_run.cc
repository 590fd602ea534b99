#include "procs/eval/vio_run.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <stdexcept>

#include "common/sim/simulator.h"
#include "procs/eval/sim_pipeline.h"

namespace vimot {
namespace eval {

SimRunResult run_vio_on_sim(const sim::SimConfig& sim_config, const estimator::VioOptions& options,
                            uint64_t perturb_seed, const SimRunOptions& ro, const InputGuardOptions& input) {
  const auto wall_start = std::chrono::steady_clock::now();
  sim::SimConfig cfg = sim_config;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);

  SimRunResult r;
  r.sim_seed = cfg.seed;
  r.perturb_seed = perturb_seed;
  r.path_length_m = sim.path_length();
  r.duration_s = sim.duration();
  r.camera_frames = sim.camera_frame_count();

  TrajectoryErrors errors;
  std::vector<PosePair> pairs;
  pairs.reserve(static_cast<std::size_t>(r.camera_frames));
  std::vector<double> cpu_ms;
  cpu_ms.reserve(static_cast<std::size_t>(r.camera_frames));
  std::map<int64_t, GroundTruth> truths;  // by utime, until the state of that utime is out
  int64_t frames_seen = 0;
  double static_obs = 0.0;
  estimator::FrameTiming stage_sum;
  const double cameras_used = options.use_stereo ? static_cast<double>(options.cameras.size()) : 1.0;

  VinsNodeOptions node_options;
  node_options.vio = options;
  node_options.init_from_ground_truth = true;
  node_options.perturb_seed = perturb_seed;
  node_options.publish_imu_rate = false;  // output only: the evaluation takes the updated states
  node_options.input = input;
  SimPipeline* pipeline = nullptr;
  VinsNode* node_ptr = nullptr;
  auto stop = [&](const std::string& why) {
    r.diverged = true;
    r.divergence_reason = why;
    pipeline->stop();
  };
  auto on_state = [&](const NavState& x) {
    if (!x.updated || pipeline->stopped()) return;
    const estimator::VioEstimator& est = node_ptr->estimator();
    const estimator::FrameTiming& ft = est.last_timing();
    cpu_ms.push_back(ft.total_cpu_ms);
    stage_sum.propagate_ms += ft.propagate_ms;
    stage_sum.msckf_ms += ft.msckf_ms;
    stage_sum.slam_update_ms += ft.slam_update_ms;
    stage_sum.slam_init_ms += ft.slam_init_ms;
    stage_sum.marginalize_ms += ft.marginalize_ms;
    stage_sum.total_ms += ft.total_ms;
    stage_sum.total_cpu_ms += ft.total_cpu_ms;
    truths.erase(truths.begin(), truths.lower_bound(x.utime));
    const auto truth = truths.find(x.utime);
    if (truth == truths.end()) {
      ++r.frames_without_truth;
      return;
    }
    FrameSample s;
    s.utime = x.utime;
    s.q_GtoI = x.q_GtoI;
    s.p_IinG = x.p_IinG;
    s.v_IinG = x.v_IinG;
    s.cov_diag = x.covariance.diagonal();
    s.q_GtoI_true = truth->second.q_GtoI;
    s.p_IinG_true = truth->second.p_IinG;
    try {
      s.error = error_of(x, truth->second);
    } catch (const std::invalid_argument& e) {
      stop("IMU covariance not positive definite at utime " + std::to_string(x.utime));
      return;
    }
    s.cpu_ms = ft.total_cpu_ms;
    s.num_slam = x.num_slam_features;
    s.num_msckf = x.num_msckf_features;
    errors.add(s.error);
    pairs.push_back(PosePair{s.q_GtoI, s.p_IinG, s.q_GtoI_true, s.p_IinG_true});
    if (ro.on_frame) ro.on_frame(est, s);
    if (ro.keep_samples) r.samples.push_back(s);
  };
  // Every error of the Node resets its estimate: the run ends there.
  VinsNode node(node_options, on_state, [&](const NodeEvent& e) {
    if (e.kind == NodeEvent::Kind::kError && !pipeline->stopped()) stop(e.message);
  });
  node_ptr = &node;
  EstimatorInputs inputs;
  inputs.on_imu = [&node](const ImuData& m) { node.on_imu(m); };
  // The truth as logged (vimot-log-eval's), not as the node normalises it.
  inputs.on_ground_truth = [&](const GroundTruth& m) {
    node.on_ground_truth(m);
    truths[m.utime] = m;
  };
  inputs.on_frame = [&](const CameraFrame& frame) {
    ++frames_seen;
    for (const FeatureObservation& o : frame.observations) {
      if (!o.is_target && o.camera_id < cameras_used) static_obs += 1.0;
    }
    node.on_frame(frame);
  };
  inputs.flush = [&node] { node.flush(); };
  SimPipeline play(sim, inputs, ro.pixels, ro.box_chain);
  pipeline = &play;
  play.run(ro.progress);
  if (ro.progress) ro.progress(1.0);

  const estimator::VioEstimator& est = node.estimator();
  r.errors = errors.summary();
  r.aligned = aligned_errors(pairs);
  if (!cpu_ms.empty()) {
    const double n = static_cast<double>(cpu_ms.size());
    r.mean_stage_ms.propagate_ms = stage_sum.propagate_ms / n;
    r.mean_stage_ms.msckf_ms = stage_sum.msckf_ms / n;
    r.mean_stage_ms.slam_update_ms = stage_sum.slam_update_ms / n;
    r.mean_stage_ms.slam_init_ms = stage_sum.slam_init_ms / n;
    r.mean_stage_ms.marginalize_ms = stage_sum.marginalize_ms / n;
    r.mean_stage_ms.total_ms = stage_sum.total_ms / n;
    r.mean_stage_ms.total_cpu_ms = stage_sum.total_cpu_ms / n;
  }
  if (frames_seen > 0) r.static_obs_per_camera = static_obs / (static_cast<double>(frames_seen) * cameras_used);
  r.timing = timing_stats(std::move(cpu_ms));
  r.totals = est.total_stats();
  r.frames_processed = est.frames_processed();
  r.frames_dropped = est.frames_dropped();
  r.target_observations_ignored = est.target_observations_ignored();
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return r;
}

std::vector<SimRunResult> run_monte_carlo(const sim::SimConfig& base, const estimator::VioOptions& options,
                                          const MonteCarloOptions& o,
                                          const std::function<void(const MonteCarloProgress&)>& progress,
                                          const InputGuardOptions& input) {
  if (o.runs < 1) throw std::invalid_argument("run_monte_carlo: runs must be >= 1, got " + std::to_string(o.runs));
  options.validate();
  input.validate();
  sim::validate(base);
  std::vector<SimRunResult> results(static_cast<std::size_t>(o.runs));
  run_parallel(
      o.runs, o.threads,
      [&](int i, const std::function<void(double)>& fr) {
        const uint64_t seed = o.first_seed + static_cast<uint64_t>(i);
        sim::SimConfig cfg = base;
        cfg.seed = seed;
        SimRunOptions ro;
        ro.keep_samples = o.keep_samples;
        ro.pixels = o.pixels;
        ro.box_chain = o.box_chain;
        ro.progress = fr;
        results[static_cast<std::size_t>(i)] = run_vio_on_sim(cfg, options, perturb_seed_of(o, seed), ro, input);
      },
      progress);
  return results;
}

}  // namespace eval
}  // namespace vimot

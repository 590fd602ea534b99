#include "procs/eval/target_run.h"

#include <algorithm>
#include <chrono>
#include <map>
#include <stdexcept>

#include "common/estimator/initial_estimate.h"
#include "common/estimator/state_helper.h"
#include "common/sim/simulator.h"
#include "common/target/target_conversion.h"
#include "common/time/utime.h"
#include "procs/eval/sim_pipeline.h"
#include "procs/target_filter/target_filter_node.h"

namespace vimot {
namespace eval {

using estimator::StateHelper;
using target::TargetFilterOptions;
using target::TargetRepresentation;
using target::TargetUpdateMode;

TargetRunResult run_target_on_sim(const sim::SimConfig& sim_config, const estimator::VioOptions& options,
                                  const std::optional<target::TargetFilterOptions>& filter_options,
                                  uint64_t perturb_seed, const std::function<void(double)>& progress,
                                  bool keep_samples, const std::optional<frontend::FeatureTrackerOptions>& pixels,
                                  const std::optional<segmentation::BoxChainOptions>& box_chain,
                                  const InputGuardOptions& input) {
  const auto wall_start = std::chrono::steady_clock::now();
  sim::SimConfig cfg = sim_config;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);
  TargetRunResult r;
  r.sim_seed = cfg.seed;
  r.perturb_seed = perturb_seed;

  // The process as config/target_filter.yaml starts it in simulation: robot
  // from the first ground truth, target perturbed with the robot's seed.
  TargetFilterNodeOptions node_options;
  node_options.vio = options;
  node_options.target_enabled = filter_options.has_value();
  if (filter_options) node_options.target = *filter_options;
  node_options.init_from_ground_truth = true;
  node_options.perturb_seed = perturb_seed;
  node_options.publish_imu_rate = false;
  node_options.input = input;

  TrajectoryErrors e_ti, e_tg, e_imu;
  std::map<int64_t, GroundTruth> truths;  // by utime, until the state of that utime is out
  std::map<int64_t, bool> target_obs;     // frames given to the node: with target observations?
  std::optional<int64_t> first_target_utime;  // of the first frame given with target observations
  int64_t gap = 0;
  int32_t frame_start = 0;  // the filter's start whose frame r.target_frame is
  int64_t used_before = 0;  // the filter's obs_used after the previous processed frame
  SimPipeline* pipeline = nullptr;
  const TargetFilterNode* node_ptr = nullptr;
  auto stop = [&](const std::string& why) {
    r.diverged = true;
    r.divergence_reason = why;
    pipeline->stop();
  };
  TargetFilterNode::Callbacks callbacks;
  callbacks.on_event = [&](const NodeEvent& e) {
    if (e.kind == NodeEvent::Kind::kError && !pipeline->stopped()) stop(e.message);
  };
  // After each processed frame (the filter's update is done by then).
  double cpu_ms_sum = 0.0;
  int64_t cpu_frames = 0;
  callbacks.on_nav_state = [&](const NavState& nav) {
    if (!nav.updated || pipeline->stopped()) return;
    const int64_t utime = nav.utime;
    const target::TargetFilter* filter = node_ptr->filter();
    const int64_t used = filter ? filter->stats().obs_used : 0;
    const bool updated_target = used > used_before;
    used_before = used;
    const auto obs = target_obs.find(utime);
    const bool has_target_obs = obs != target_obs.end() && obs->second;
    target_obs.erase(target_obs.begin(), target_obs.upper_bound(utime));
    truths.erase(truths.begin(), truths.lower_bound(utime));
    const auto t_it = truths.find(utime);
    if (t_it == truths.end() || !first_target_utime || *first_target_utime > utime) return;
    const GroundTruth& truth = t_it->second;
    gap = has_target_obs ? 0 : gap + 1;
    r.longest_gap_frames = std::max(r.longest_gap_frames, gap);
    r.frames_with_target_obs += has_target_obs ? 1 : 0;
    if (filter) r.frames_with_target_update += updated_target ? 1 : 0;
    const estimator::VioEstimator& est = node_ptr->estimator();
    cpu_ms_sum += est.last_timing().total_cpu_ms;
    ++cpu_frames;
    try {
      e_imu.add(error_of(nav, truth));
      if (filter && filter->initialized() && truth.has_target) {
        if (!r.target_initialized) r.target_init_s = utime_to_seconds(utime - *first_target_utime);
        r.target_initialized = true;
        const estimator::State& s = est.state();
        const target::PoseValue ip = target::imu_pose(est.imu_value());
        const target::TargetValue x = filter->value();
        const Eigen::Matrix<double, 18, 18> P18 =
            StateHelper::marginal_covariance(s, {s.imu()->pose()->q(), s.imu()->pose()->p(), filter->target()});
        target::TargetValue x_i, x_g;
        target::Matrix12d P_i, P_g;
        if (filter->options().representation == TargetRepresentation::kLocal) {
          x_i = x;
          P_i = P18.block<12, 12>(6, 6);
          x_g = target::local_to_global(ip, x);
          P_g = target::local_to_global_covariance(ip, x, P18);
        } else {
          x_g = x;
          P_g = P18.block<12, 12>(6, 6);
          x_i = target::global_to_local(ip, x);
          P_i = target::global_to_local_covariance(ip, x, P18);
        }
        // A frame of the filter's own (features start): fixed at its first
        // estimate, taken again when the filter starts the target again.
        if (filter->starts() != frame_start && filter->options().init_mode == target::TargetInitMode::kFeatures) {
          frame_start = filter->starts();
          r.target_frame = target_frame_transform(truth, x_i.q_RtoT, x_i.p_TinR);
        }
        const GroundTruth t = in_target_frame(truth, r.target_frame);
        const TargetInImu truth_in_imu = true_target_in_imu(t);
        const ErrorSample ti = compute_error(utime, truth_in_imu.q_ItoT, truth_in_imu.p_TinI, x_i.q_RtoT, x_i.p_TinR,
                                             P_i.block<3, 3>(0, 0), P_i.block<3, 3>(3, 3));
        const ErrorSample tg = compute_error(utime, t.q_GtoT, t.p_TinG, x_g.q_RtoT, x_g.p_TinR,
                                             P_g.block<3, 3>(0, 0), P_g.block<3, 3>(3, 3));
        e_ti.add(ti);
        e_tg.add(tg);
        r.target_max_error_m = std::max(r.target_max_error_m, ti.err_p.norm());
        if (keep_samples) {
          r.target_in_imu_samples.push_back(ti);
          r.target_in_world_samples.push_back(tg);
        }
      }
    } catch (const std::invalid_argument& e) {
      stop("covariance not positive definite at utime " + std::to_string(utime) + ": " + e.what());
    }
  };
  TargetFilterNode node(node_options, callbacks);
  node_ptr = &node;
  EstimatorInputs inputs;
  inputs.on_imu = [&node](const ImuData& m) { node.on_imu(m); };
  inputs.on_ground_truth = [&](const GroundTruth& m) {
    node.on_ground_truth(m);
    truths[m.utime] = m;
  };
  inputs.on_frame = [&](const CameraFrame& frame) {
    bool has = false;
    for (const FeatureObservation& o : frame.observations) has = has || o.is_target;
    if (has && !first_target_utime) first_target_utime = frame.utime;
    target_obs[frame.utime] = has;
    node.on_frame(frame);
  };
  inputs.flush = [&node] { node.flush(); };
  SimPipeline play(sim, inputs, pixels, box_chain);
  pipeline = &play;
  play.run(progress);
  if (progress) progress(1.0);
  r.target_in_imu = e_ti.summary();
  r.target_in_world = e_tg.summary();
  r.imu = e_imu.summary();
  r.frames_processed = node.frames_processed();
  r.cpu_ms_per_frame = cpu_frames > 0 ? cpu_ms_sum / static_cast<double>(cpu_frames) : 0.0;
  if (node.filter()) r.target_stats = node.filter()->stats();
  if (node.filter() && !r.diverged && filter_options->mode != TargetUpdateMode::kOff && !r.target_initialized) {
    r.diverged = true;
    r.divergence_reason = "target never initialised";
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return r;
}

std::vector<TargetCell> run_target_sweep(const sim::SimConfig& base, const estimator::VioOptions& options,
                                         const target::TargetFilterOptions& base_filter, const TargetSweepOptions& o,
                                         const std::function<void(const MonteCarloProgress&)>& progress,
                                         const InputGuardOptions& input) {
  if (o.runs < 1) throw std::invalid_argument("run_target_sweep: runs must be >= 1, got " + std::to_string(o.runs));
  options.validate();
  input.validate();
  sim::validate(base);
  std::vector<TargetCell> cells;
  if (o.vio_only) {
    TargetCell c;
    c.vio_only = true;
    cells.push_back(c);
  }
  for (TargetUpdateMode m : o.modes) {
    for (TargetRepresentation rep : o.representations) {
      for (double sigma : o.sigmas) {
        TargetCell c;
        c.filter = base_filter;
        c.filter.mode = m;
        c.filter.representation = rep;
        c.filter.sigma_t = sigma;
        cells.push_back(c);
      }
    }
  }
  if (cells.empty()) throw std::invalid_argument("run_target_sweep: nothing to run");
  for (TargetCell& c : cells) c.runs.resize(static_cast<std::size_t>(o.runs));
  const int jobs = static_cast<int>(cells.size()) * o.runs;
  run_parallel(
      jobs, o.threads,
      [&](int j, const std::function<void(double)>& fr) {
        TargetCell& c = cells[static_cast<std::size_t>(j / o.runs)];
        const int i = j % o.runs;
        const uint64_t seed = o.first_seed + static_cast<uint64_t>(i);
        sim::SimConfig cfg = base;
        cfg.seed = seed;
        std::optional<TargetFilterOptions> f;
        if (!c.vio_only) f = c.filter;
        c.runs[static_cast<std::size_t>(i)] =
            run_target_on_sim(cfg, options, f, o.fixed_perturb_seed.value_or(estimator::perturb_seed_for_run(seed)), fr,
                              o.keep_samples, o.pixels, o.box_chain, input);
      },
      progress);
  return cells;
}

}  // namespace eval
}  // namespace vimot

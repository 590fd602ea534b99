#include "common/eval/sim_runner.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <variant>

#include "common/estimator/initial_estimate.h"
#include "common/estimator/nav_state_of.h"
#include "common/sim/simulator.h"

namespace vimot {
namespace eval {

using estimator::FrameStatus;
using estimator::VioEstimator;

void play_simulator(sim::Simulator& sim, estimator::VioEstimator& estimator,
                    const std::function<void(const GroundTruth&)>& on_truth,
                    const std::function<bool(const CameraFrame&)>& on_frame, PixelFrontEnd* pixels) {
  while (std::optional<sim::SimEvent> ev = sim.next()) {
    if (const auto* imu = std::get_if<ImuData>(&*ev)) {
      estimator.feed_imu(*imu);
    } else if (const auto* gt = std::get_if<GroundTruth>(&*ev)) {
      on_truth(*gt);
    } else {
      const CameraFrame& simulated = std::get<CameraFrame>(*ev);
      if (!on_frame(pixels ? pixels->frame(simulated.utime) : simulated)) return;
    }
  }
}

SimRunResult run_vio_on_sim(const sim::SimConfig& sim_config, const estimator::VioOptions& options,
                            uint64_t perturb_seed, const SimRunOptions& ro) {
  const auto wall_start = std::chrono::steady_clock::now();
  sim::SimConfig cfg = sim_config;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);
  VioEstimator est(options);
  std::optional<PixelFrontEnd> pixels;
  if (ro.pixels) pixels.emplace(sim, *ro.pixels, ro.box_chain);

  SimRunResult r;
  r.sim_seed = cfg.seed;
  r.perturb_seed = perturb_seed;
  r.path_length_m = sim.path_length();
  r.duration_s = sim.duration();
  r.camera_frames = sim.camera_frame_count();

  const estimator::InitialEstimate x0 = estimator::initial_estimate(sim.initial_state(), options, perturb_seed);
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);

  TrajectoryErrors errors;
  std::vector<PosePair> pairs;
  pairs.reserve(static_cast<std::size_t>(r.camera_frames));
  std::vector<double> cpu_ms;
  cpu_ms.reserve(static_cast<std::size_t>(r.camera_frames));
  GroundTruth last_truth;
  bool have_truth = false;
  int64_t frames_seen = 0;
  double static_obs = 0.0;
  estimator::FrameTiming stage_sum;
  const double cameras_used = options.use_stereo ? static_cast<double>(options.cameras.size()) : 1.0;

  auto on_truth = [&](const GroundTruth& gt) {
    last_truth = gt;
    have_truth = true;
  };
  play_simulator(sim, est, on_truth, [&](const CameraFrame& frame) {
    ++frames_seen;
    for (const FeatureObservation& o : frame.observations) {
      if (!o.is_target && o.camera_id < cameras_used) static_obs += 1.0;
    }
    const FrameStatus st = est.feed_camera(frame);
    if (ro.progress) ro.progress(static_cast<double>(frames_seen) / static_cast<double>(std::max<int64_t>(1, r.camera_frames)));
    if (st == FrameStatus::kDiverged) {
      r.diverged = true;
      r.divergence_reason = est.last_divergence().reason;
      return false;
    }
    if (st != FrameStatus::kProcessed) return true;
    const estimator::FrameTiming& ft = est.last_timing();
    cpu_ms.push_back(ft.total_cpu_ms);
    stage_sum.propagate_ms += ft.propagate_ms;
    stage_sum.msckf_ms += ft.msckf_ms;
    stage_sum.slam_update_ms += ft.slam_update_ms;
    stage_sum.slam_init_ms += ft.slam_init_ms;
    stage_sum.marginalize_ms += ft.marginalize_ms;
    stage_sum.total_ms += ft.total_ms;
    stage_sum.total_cpu_ms += ft.total_cpu_ms;
    // At equal utime the simulator emits IMU, GroundTruth, CameraFrame: the
    // truth of this frame, if any, is the last GroundTruth event.
    if (!have_truth || last_truth.utime != frame.utime) {
      ++r.frames_without_truth;
      return true;
    }
    const NavState x = estimator::nav_state_of(est, true);
    FrameSample s;
    s.utime = x.utime;
    s.q_GtoI = x.q_GtoI;
    s.p_IinG = x.p_IinG;
    s.v_IinG = x.v_IinG;
    s.cov_diag = x.covariance.diagonal();
    s.q_GtoI_true = last_truth.q_GtoI;
    s.p_IinG_true = last_truth.p_IinG;
    try {
      s.error = error_of(x, last_truth);
    } catch (const std::invalid_argument& e) {
      r.diverged = true;
      r.divergence_reason = "IMU covariance not positive definite at utime " + std::to_string(x.utime);
      return false;
    }
    s.cpu_ms = est.last_timing().total_cpu_ms;
    s.num_slam = x.num_slam_features;
    s.num_msckf = x.num_msckf_features;
    errors.add(s.error);
    pairs.push_back(PosePair{s.q_GtoI, s.p_IinG, s.q_GtoI_true, s.p_IinG_true});
    if (ro.on_frame) ro.on_frame(est, s);
    if (ro.keep_samples) r.samples.push_back(s);
    return true;
  }, pixels ? &*pixels : nullptr);
  if (ro.progress) ro.progress(1.0);

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

uint64_t perturb_seed_of(const MonteCarloOptions& o, uint64_t sim_seed) {
  if (!o.perturb) return 0;
  return o.fixed_perturb_seed != 0 ? o.fixed_perturb_seed : estimator::perturb_seed_for_run(sim_seed);
}

void run_parallel(int jobs, int threads_wanted, const std::function<void(int, const std::function<void(double)>&)>& job,
                  const std::function<void(const MonteCarloProgress&)>& progress) {
  if (jobs < 1) throw std::invalid_argument("run_parallel: jobs must be >= 1, got " + std::to_string(jobs));
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = std::max(1, std::min(threads_wanted > 0 ? threads_wanted : hw, jobs));
  const auto start = std::chrono::steady_clock::now();

  std::vector<std::atomic<double>> fraction(static_cast<std::size_t>(jobs));
  for (auto& f : fraction) f = 0.0;
  std::atomic<int> next{0};
  std::atomic<int> done{0};
  std::atomic<bool> failed{false};
  std::exception_ptr first_error;
  std::mutex mutex;
  std::condition_variable cv;

  auto worker = [&] {
    for (int i = next++; i < jobs && !failed; i = next++) {
      try {
        std::atomic<double>& fr = fraction[static_cast<std::size_t>(i)];
        job(i, [&fr](double f) { fr = f; });
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!first_error) first_error = std::current_exception();
        failed = true;
      }
      {
        std::lock_guard<std::mutex> lock(mutex);
        ++done;
      }
      cv.notify_all();
    }
  };

  auto report = [&] {
    if (!progress) return;
    MonteCarloProgress p;
    p.runs_done = done;
    p.runs_total = jobs;
    double sum = 0.0;
    for (const auto& f : fraction) sum += f;
    p.fraction = std::min(1.0, sum / jobs);
    p.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress(p);
  };

  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) pool.emplace_back(worker);
  {
    std::unique_lock<std::mutex> lock(mutex);
    while (done < jobs && !failed) {
      cv.wait_for(lock, std::chrono::milliseconds(250));
      lock.unlock();
      report();
      lock.lock();
    }
  }
  for (auto& t : pool) t.join();
  if (first_error) std::rethrow_exception(first_error);
  report();
}

std::vector<SimRunResult> run_monte_carlo(const sim::SimConfig& base, const estimator::VioOptions& options,
                                          const MonteCarloOptions& o,
                                          const std::function<void(const MonteCarloProgress&)>& progress) {
  if (o.runs < 1) throw std::invalid_argument("run_monte_carlo: runs must be >= 1, got " + std::to_string(o.runs));
  options.validate();
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
        results[static_cast<std::size_t>(i)] = run_vio_on_sim(cfg, options, perturb_seed_of(o, seed), ro);
      },
      progress);
  return results;
}

MonteCarloSummary aggregate(const std::vector<SimRunResult>& runs) {
  std::vector<ErrorSummary> s;
  s.reserve(runs.size());
  for (const auto& r : runs) s.push_back(r.errors);
  return aggregate(s);
}

}  // namespace eval
}  // namespace vimot

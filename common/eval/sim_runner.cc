#include "common/eval/sim_runner.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <variant>

#include "common/estimator/initial_estimate.h"
#include "common/sim/simulator.h"

namespace vimot {
namespace eval {

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

MonteCarloSummary aggregate(const std::vector<SimRunResult>& runs) {
  std::vector<ErrorSummary> s;
  s.reserve(runs.size());
  for (const auto& r : runs) s.push_back(r.errors);
  return aggregate(s);
}

}  // namespace eval
}  // namespace vimot

#pragma once
// The estimator on the simulator, evaluated against the simulator's truth:
// what a run and a Monte Carlo measure. The runs themselves drive the
// `vins` process's Node fed the simulator's messages as over LCM
// (procs/eval/vio_run.h, vimot-vio-eval), so this library holds only their
// results and the parts that need no process.
//
// One run: the simulator (GroundTruth events on) plays into VinsNode, which
// starts from the first ground truth perturbed by initial_estimate(...,
// perturb_seed). The evaluation samples are the states the node publishes
// after each processed camera frame (VINS_STATE, updated = true), each
// compared with the GroundTruth of the same utime (error_of,
// common/eval/metrics.h). A frame the estimator does not process (no IMU)
// gives no sample; a reset of the node (divergence) ends the run, said so.
//
// Monte Carlo: run i uses simulator seed first_seed + i (new noise, same
// truth and map) and perturbation seed perturb_seed_for_run(first_seed + i).
// Runs are independent and deterministic, so the results are the same
// whatever the thread count (only the CPU times differ). No LCM here.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/eval/alignment.h"
#include "common/eval/metrics.h"
#include "common/eval/pixel_frontend.h"
#include "common/frontend/tracker_options.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"

namespace vimot {
namespace eval {

/// One evaluation sample: the state after a camera update and its errors.
struct FrameSample {
  int64_t utime{0};                                  // µs
  Eigen::Vector4d q_GtoI{0.0, 0.0, 0.0, 1.0};        // estimate, JPL
  Eigen::Vector3d p_IinG{Eigen::Vector3d::Zero()};    // estimate, m
  Eigen::Vector3d v_IinG{Eigen::Vector3d::Zero()};    // estimate, m/s
  Eigen::Matrix<double, 15, 1> cov_diag{Eigen::Matrix<double, 15, 1>::Zero()};  // [δθ δp δv δbg δba]
  Eigen::Vector4d q_GtoI_true{0.0, 0.0, 0.0, 1.0};
  Eigen::Vector3d p_IinG_true{Eigen::Vector3d::Zero()};
  ErrorSample error;
  double cpu_ms{0.0};        // CPU time of this frame's feed_camera (thread CPU clock)
  int num_slam{0};           // SLAM landmarks in the state after the frame
  int num_msckf{0};          // MSCKF features used in this frame
};

struct SimRunOptions {
  bool keep_samples{true};  // false: only the summary (long Monte Carlo)
  /// Set: frames from pixels — rendered images through the feature tracker
  /// with these options instead of the simulated tracks.
  std::optional<frontend::FeatureTrackerOptions> pixels;
  /// With pixels: the target box from the segmenter and mask filter
  /// instead of the truth.
  std::optional<segmentation::BoxChainOptions> box_chain;
  /// Fraction of the run's camera frames done, after every frame (called
  /// on the thread running the simulation).
  std::function<void(double)> progress;
  /// After every sample, with the estimator (tests, custom metrics).
  std::function<void(const estimator::VioEstimator&, const FrameSample&)> on_frame;
};

struct SimRunResult {
  uint64_t sim_seed{0};
  uint64_t perturb_seed{0};
  std::vector<FrameSample> samples;  // empty unless keep_samples
  ErrorSummary errors;
  /// ATE after a yaw + translation alignment (alignment.h), for comparison
  /// with OpenVINS's ov_eval figures only.
  AlignedErrors aligned;
  TimingStats timing;                // per processed frame, CPU ms
  estimator::FrameTiming mean_stage_ms;  // per-stage wall-clock ms, mean over processed frames
  double static_obs_per_camera{0.0};  // mean static observations per camera and frame
  estimator::UpdateStats totals;     // summed over the run
  double path_length_m{0.0};         // of the simulated IMU path
  double duration_s{0.0};            // simulated
  int64_t camera_frames{0};          // emitted by the simulator
  int64_t frames_processed{0};
  int64_t frames_dropped{0};
  int64_t frames_without_truth{0};   // processed, but no GroundTruth at that utime
  int64_t target_observations_ignored{0};
  bool diverged{false};
  std::string divergence_reason;
  double wall_s{0.0};
};

/// Plays the simulator's events in time order into an estimator: IMU samples
/// go to `estimator`, ground truth to `on_truth`, camera frames to
/// `on_frame`, which returns false to stop. At equal utime the simulator
/// emits IMU, GroundTruth, CameraFrame, so a frame's truth (if any) has
/// arrived before it. With `pixels`, each camera frame is replaced by the
/// features `pixels` tracks in the images rendered at its utime.
void play_simulator(sim::Simulator& sim, estimator::VioEstimator& estimator,
                    const std::function<void(const GroundTruth&)>& on_truth,
                    const std::function<bool(const CameraFrame&)>& on_frame, PixelFrontEnd* pixels = nullptr);

struct MonteCarloOptions {
  int runs{30};
  uint64_t first_seed{1};
  int threads{0};                  // 0: std::thread::hardware_concurrency()
  bool perturb{true};              // false: every run starts exactly at the truth
  bool keep_samples{true};
  std::optional<frontend::FeatureTrackerOptions> pixels;  // as SimRunOptions::pixels
  std::optional<segmentation::BoxChainOptions> box_chain;  // as SimRunOptions::box_chain
  /// Nonzero: every run uses this perturbation seed (to reproduce one run
  /// of the `vins` process, whose config names its seed).
  uint64_t fixed_perturb_seed{0};
};

/// Progress of a Monte Carlo: runs finished and the total fraction done.
struct MonteCarloProgress {
  int runs_done{0};
  int runs_total{0};
  double fraction{0.0};  // in [0, 1], counting partly done runs
  double elapsed_s{0.0};
};

/// Runs job(i, progress_i) for i in [0, jobs) on `threads` std::threads
/// (0: hardware concurrency; at most `jobs`), each job on one thread;
/// progress_i(f) reports job i's fraction done (thread-safe). `progress` is
/// called on the calling thread about every 0.25 s and once at the end
/// (runs_* count jobs). The first exception of a job is rethrown after all
/// threads are joined. The building block of every Monte Carlo here: jobs
/// write their own result slot, so results do not depend on `threads`.
void run_parallel(int jobs, int threads, const std::function<void(int, const std::function<void(double)>&)>& job,
                  const std::function<void(const MonteCarloProgress&)>& progress = {});

/// Perturbation seed of run with simulator seed `sim_seed` under `o`.
uint64_t perturb_seed_of(const MonteCarloOptions& o, uint64_t sim_seed);

/// The per-run error summaries of a Monte Carlo, aggregated.
MonteCarloSummary aggregate(const std::vector<SimRunResult>& runs);

}  // namespace eval
}  // namespace vimot

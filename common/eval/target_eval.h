#pragma once
// The joint robot + target filter (common/target/target_filter.h) on the
// simulator, evaluated against its truth: what one run and the σ_t sweep of
// Eckenhoff et al., "Schmidt-EKF-based Visual-Inertial Moving Object
// Tracking", Sec. IV (Tables I and II) measure, and their tables and
// summary files (vimot-target-eval). The runs drive the `target_filter`
// process's Node fed the simulator's messages as over LCM
// (procs/eval/target_run.h). No LCM here.
//
// One run is vimot-vio-eval's run (same simulator, same perturbed IMU start
// initial_estimate(..., perturb_seed)) with the TargetFilter attached (none
// for the VIO-only row); the node buffers the ground truth and gives the
// filter the truth of a frame's utime, which it uses only with init mode
// ground_truth (the target initialised from the truth at the first frame
// with target observations, as in tests/target/target_filter_test.cc); with
// init mode features the filter starts from its own target features and the
// truth is taken in the filter's target frame (target_frame.h, fixed at the
// filter's first estimate, reported in TargetRunResult::target_frame).
// Samples: every processed frame with truth at or after the first frame with
// target observations (the same frames with and without the filter); the
// target errors only once the filter is initialised. Per sample (error
// conventions of metrics.h, the target's left error R = Exp(−δθ) R̂ for the
// orientations):
//  * target in IMU [q_ItoT, p_TinI]: local directly, global through
//    global_to_local (covariance by global_to_local_covariance);
//  * target in world [q_GtoT, p_TinG]: global directly, local through
//    local_to_global (local_to_global_covariance);
//  * IMU in world: error_of(the published NAV_STATE, truth), as
//    vimot-vio-eval.
// RMSE and mean NEES per run (TrajectoryErrors); a cell of the sweep
// averages its runs (diverged runs are left out and counted).
// From pixels (`pixels` set): the frames are the features the feature
// tracker Node tracks in the rendered images (true box, or with a box chain
// the segmenter and mask filter Nodes' box), as vimot-vio-eval --pixels;
// the truth and the samples are the same.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/eval/metrics.h"
#include "common/eval/sim_runner.h"
#include "common/eval/target_frame.h"
#include "common/frontend/tracker_options.h"
#include "common/segmentation/box_chain.h"
#include "common/target/target_filter.h"

namespace vimot {
namespace eval {

/// TargetFilterOptions from the `target:` section of a target_filter config
/// (common/target/target_filter_config.h; mode none is refused: the sweep
/// runs its VIO-only cells itself). Throws ConfigError naming the key.
target::TargetFilterOptions target_filter_options(const Config& config);

struct TargetRunResult {
  uint64_t sim_seed{0};
  uint64_t perturb_seed{0};
  ErrorSummary target_in_imu;    // [q_ItoT, p_TinI]
  ErrorSummary target_in_world;  // [q_GtoT, p_TinG]
  ErrorSummary imu;              // [q_GtoI, p_IinG]
  bool target_initialized{false};
  /// The filter's target frame in the true one, taken at its first estimate
  /// and again at the first estimate of each new start (init mode features;
  /// the last one taken); identity for the start from the truth.
  TargetFrameTransform target_frame;
  int64_t frames_processed{0};
  /// Whether the target was tracked through the run, counted over the
  /// evaluated frames (imu.count: processed, with truth, from the first
  /// frame with target observations on): with a target estimate
  /// (target_in_imu.count), with target observations, with target
  /// observations used in an update (in-state points, new points or
  /// tracks); the longest run of evaluated frames without target
  /// observations; the largest target-in-IMU position error (a target lost
  /// by the filter shows there, not in the frame counts: it never drops an
  /// initialised target).
  int64_t frames_with_target_obs{0};
  int64_t frames_with_target_update{0};
  int64_t longest_gap_frames{0};
  double target_max_error_m{0.0};
  double target_init_s{0.0};  // s from the first frame with target observations to the target's start
  /// The filter's counters at the end (which target tracks and points were
  /// used or rejected, and why).
  target::TargetUpdateStats target_stats;
  bool diverged{false};
  std::string divergence_reason;
  double wall_s{0.0};
  /// Mean thread CPU time of the estimator's frame (VIO and target filter
  /// together, FrameTiming::total_cpu_ms) over the evaluated frames; load
  /// dependent.
  double cpu_ms_per_frame{0.0};
  /// Per-frame errors with 3σ bounds (only when asked for: keep_samples).
  std::vector<ErrorSample> target_in_imu_samples;
  std::vector<ErrorSample> target_in_world_samples;
};

/// One cell of the sweep: a filter configuration (or VIO only) × runs.
struct TargetCell {
  bool vio_only{false};
  target::TargetFilterOptions filter;  // mode, representation, sigma_t set per cell
  std::vector<TargetRunResult> runs;
};

/// Mean over the non-diverged runs of a cell.
struct TargetCellSummary {
  int runs{0};
  int diverged{0};
  MonteCarloSummary target_in_imu;
  MonteCarloSummary target_in_world;
  MonteCarloSummary imu;
};
TargetCellSummary summarize(const TargetCell& cell);

struct TargetSweepOptions {
  std::vector<double> sigmas{0.001, 0.005, 0.01, 0.05, 0.1, 0.5};
  std::vector<target::TargetUpdateMode> modes{target::TargetUpdateMode::kEkf, target::TargetUpdateMode::kSkf};
  std::vector<target::TargetRepresentation> representations{target::TargetRepresentation::kGlobal,
                                                            target::TargetRepresentation::kLocal};
  bool vio_only{true};  // add the VIO-only cell (first)
  int runs{30};
  uint64_t first_seed{1};
  int threads{0};
  bool keep_samples{false};  // TargetRunResult::*_samples of every run
  /// Perturbation seed of every run instead of perturb_seed_for_run (0 =
  /// start at the truth), e.g. the vins config's, to reproduce an LCM run.
  std::optional<uint64_t> fixed_perturb_seed;
  /// Frames from pixels (run_target_on_sim's `pixels`).
  std::optional<frontend::FeatureTrackerOptions> pixels;
  std::optional<segmentation::BoxChainOptions> box_chain;  // as run_target_on_sim's
};

/// Markdown tables in the layout of the paper's Tables I (EKF) and II (SKF):
/// rows σ_t, column groups global | local, each "target in IMU, target in
/// world, IMU in world" as "m / deg"; then the VIO-only row and a NEES
/// table. "×" marks a cell whose runs all diverged, "(k div)" some.
std::string target_tables(const std::vector<TargetCell>& cells);

/// summary.json: context and one object per cell (means, std, per run).
std::string target_summary_json(const std::vector<TargetCell>& cells, const std::string& sim_config,
                                const std::string& vins_config, const std::string& target_config,
                                const TargetSweepOptions& o, double wall_s);

/// The cells of a summary.json written by target_summary_json (per-run
/// figures; options beyond mode, representation and σ_t are not stored), so
/// sweeps run in parts can be tabulated together. Throws std::runtime_error
/// naming the file.
std::vector<TargetCell> read_target_cells(const std::string& summary_json);

/// summary.csv: one row per cell and run, then per cell a row run = "mean".
std::string target_summary_csv(const std::vector<TargetCell>& cells);

}  // namespace eval
}  // namespace vimot

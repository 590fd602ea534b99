#pragma once
// Tables and summary files of a Monte Carlo of run_vio_on_sim runs (the
// output of vimot-vio-eval). No LCM here.

#include <cstdint>
#include <string>
#include <vector>

#include "common/eval/machine.h"
#include "common/eval/sim_runner.h"

namespace vimot {
namespace eval {

/// What was run, for the summary files.
struct RunContext {
  std::string sim_config;
  std::string vins_config;
  uint64_t first_seed{1};
  bool perturb{true};
  int threads{1};
  double wall_s{0.0};
  MachineInfo machine;
};

/// Mean of the per-run figures (timing: mean of means, medians and p95s, max
/// of maxima; counts: mean per run).
struct RunAverages {
  MonteCarloSummary errors;
  double ate4_position_m{0.0};       // mean over runs of the 4-DoF-aligned ATE
  double ate4_orientation_deg{0.0};
  double path_length_m{0.0};
  TimingStats timing;
  double frames{0.0};
  double msckf_used{0.0};
  double slam_initialized{0.0};
  double slam_updated{0.0};
  int diverged{0};
};
RunAverages average_runs(const std::vector<SimRunResult>& runs);

/// The table vimot-vio-eval prints: one row per run and the average row.
std::string results_table(const std::vector<SimRunResult>& runs);

/// summary.json: context, "summary" (means over runs, readable by
/// read_summary_json), "std", "timing", "runs" (one object per run).
std::string summary_json(const std::vector<SimRunResult>& runs, const RunContext& context);

/// summary.csv: one row per run, then a row "mean".
std::string summary_csv(const std::vector<SimRunResult>& runs);

}  // namespace eval
}  // namespace vimot

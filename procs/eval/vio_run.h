#pragma once
// The `vins` process on the simulator, offline (vimot-vio-eval): its Node
// (VinsNode) fed the simulator's messages as over LCM (sim_pipeline.h) and
// its published states evaluated against the simulator's truth
// (common/eval/sim_runner.h says what a run and a Monte Carlo measure).

#include <cstdint>
#include <functional>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/eval/sim_runner.h"
#include "common/sim/sim_config.h"
#include "procs/vins/vins_node.h"

namespace vimot {
namespace eval {

/// One run on `sim_config` (its seed and duration as given): VinsNode with
/// `options`, started from the first ground truth perturbed with
/// `perturb_seed`, and the input guards `input` (the vins config's `input`
/// section). A reset of the Node (divergence, an inconsistent filter) ends
/// the run as diverged, with the Node's reason.
SimRunResult run_vio_on_sim(const sim::SimConfig& sim_config, const estimator::VioOptions& options,
                            uint64_t perturb_seed, const SimRunOptions& run_options = {},
                            const InputGuardOptions& input = {});

/// Runs o.runs independent runs on o.threads std::threads; results in run
/// order. `progress` is called on the calling thread, about every 0.25 s
/// and once at the end. The first exception of a run is rethrown after all
/// threads are joined.
std::vector<SimRunResult> run_monte_carlo(const sim::SimConfig& base, const estimator::VioOptions& options,
                                          const MonteCarloOptions& o,
                                          const std::function<void(const MonteCarloProgress&)>& progress = {},
                                          const InputGuardOptions& input = {});

}  // namespace eval
}  // namespace vimot

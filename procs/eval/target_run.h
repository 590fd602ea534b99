#pragma once
// The `target_filter` process on the simulator, offline (vimot-target-eval):
// its Node (TargetFilterNode) fed the simulator's messages as over LCM
// (sim_pipeline.h), evaluated after every processed frame against the
// simulator's truth; common/eval/target_eval.h says what a run and the σ_t
// sweep measure, and tabulates them.

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/eval/target_eval.h"
#include "common/frontend/tracker_options.h"
#include "common/segmentation/box_chain.h"
#include "common/sim/sim_config.h"
#include "common/target/target_filter.h"
#include "procs/vins/vins_node.h"

namespace vimot {
namespace eval {

/// One run on `sim_config` (its seed and duration); filter == nullopt: VIO
/// only (the node with no filter attached). `progress` gets the fraction of
/// camera frames done. keep_samples: also return the per-frame target
/// errors. pixels: frames from the rendered images through the feature
/// tracker with these options; box_chain (with pixels): the target box from
/// the segmenter and mask filter, not the truth. `input`: the node's input
/// guards (the vins config's `input` section). A reset of the node ends the
/// run as diverged, with the node's reason.
TargetRunResult run_target_on_sim(const sim::SimConfig& sim_config, const estimator::VioOptions& options,
                                  const std::optional<target::TargetFilterOptions>& filter, uint64_t perturb_seed,
                                  const std::function<void(double)>& progress = {}, bool keep_samples = false,
                                  const std::optional<frontend::FeatureTrackerOptions>& pixels = std::nullopt,
                                  const std::optional<segmentation::BoxChainOptions>& box_chain = std::nullopt,
                                  const InputGuardOptions& input = {});

/// Every cell (VIO only first, then modes × representations × sigmas in
/// that nesting) × runs on o.threads threads (run_parallel); run i of every
/// cell uses simulator seed first_seed + i and perturbation seed
/// perturb_seed_for_run(first_seed + i). Deterministic whatever the thread
/// count. `base_filter` gives the options not swept.
std::vector<TargetCell> run_target_sweep(const sim::SimConfig& base, const estimator::VioOptions& options,
                                         const target::TargetFilterOptions& base_filter, const TargetSweepOptions& o,
                                         const std::function<void(const MonteCarloProgress&)>& progress = {},
                                         const InputGuardOptions& input = {});

}  // namespace eval
}  // namespace vimot

#pragma once
// The monocular metric-scale pipeline of the scale paper (Qiu et al.,
// Sec. III-IV) on the simulator, offline and in-process (vimot-scale-eval),
// evaluated with common/eval/scale_eval.h. The same Node classes as the LCM
// processes, fed in the same order: per camera frame VioEstimator (mono) ->
// NavState, ObjectTrackerNode -> up-to-scale object pose, ScaleNode
// (pairing by utime, correlation estimator, held scale, Eq. 20-21). No LCM.

#include <cstdint>
#include <functional>
#include <optional>

#include "common/estimator/vio_estimator.h"
#include "common/eval/scale_eval.h"
#include "common/frontend/tracker_options.h"
#include "common/object/object_tracker.h"
#include "common/segmentation/box_chain.h"
#include "common/sim/sim_config.h"
#include "procs/scale_estimator/scale_node.h"

namespace vimot {
namespace eval {

struct ScaleEvalOptions {
  estimator::VioOptions vio;
  ObjectTrackerOptions tracker;
  ScaleNodeOptions node;
  /// Set: frames from pixels (common/eval/pixel_frontend.h) instead of the
  /// simulated tracks.
  std::optional<frontend::FeatureTrackerOptions> pixels;
  /// With pixels: the target box from the segmenter and mask filter.
  std::optional<segmentation::BoxChainOptions> box_chain;
};

/// One run on `sim_config` (mono scenario with a target). perturb_seed 0 =
/// the VIO starts at the truth. `progress` gets the fraction of frames done.
/// Throws std::invalid_argument on a scenario without a target or camera.
ScaleRunResult run_scale_on_sim(const sim::SimConfig& sim_config, const ScaleEvalOptions& options,
                                uint64_t perturb_seed, const std::function<void(double)>& progress = {});

}  // namespace eval
}  // namespace vimot

#pragma once
// Feature frames from pixels, offline: the rendered simulator's images of a
// camera frame (common/sim/renderer.h) through the feature tracker
// (common/frontend), with the target box the renderer reports as truth —
// what `vimot-sim --render` → `vimot-feature-tracker` (target box channel
// TARGET_BOX_TRUTH, node.wait_for_box) computes over LCM, so an evaluator
// fed by this front end gives the figures of that LCM pipeline.
// With a BoxChain (common/segmentation/box_chain.h) the box comes instead
// from the segmenter and the mask filter, as `vimot-segmenter` →
// `vimot-mask-filter` → `vimot-feature-tracker` (TARGET_BOX) over LCM: no
// ground truth in the chain (backend onnx). With tracker.target.use_mask the
// tracker gets the view's true mask (TARGET_MASK_TRUTH) or the segmenter's
// (TARGET_MASK), as the node pairs them.

#include <cstdint>
#include <optional>
#include <vector>

#include "common/frontend/feature_tracker.h"
#include "common/frontend/tracker_options.h"
#include "common/segmentation/box_chain.h"
#include "common/sim/renderer.h"
#include "common/sim/simulator.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace eval {

class PixelFrontEnd {
 public:
  /// Renders `sim`'s cameras (which must outlive this) and tracks with
  /// `options` on the simulator's own calibrations; the target box from
  /// `boxes` (one filter per rendered camera) when given, else the truth.
  PixelFrontEnd(const sim::Simulator& sim, const frontend::FeatureTrackerOptions& options,
                const std::optional<segmentation::BoxChainOptions>& boxes = std::nullopt);

  /// The tracked features of the images at `utime` (a camera frame's time).
  CameraFrame frame(int64_t utime);

  const frontend::FeatureTracker& tracker() const { return tracker_; }
  const sim::Renderer& renderer() const { return renderer_; }
  /// The rendered views of the last frame() (truth: masks, boxes).
  const std::vector<sim::RenderedView>& last_views() const { return views_; }
  /// With a box chain: each camera's box estimate of the last frame().
  const std::vector<segmentation::BoxEstimate>& last_boxes() const { return boxes_; }
  const segmentation::BoxChain* box_chain() const { return chain_ ? &*chain_ : nullptr; }

 private:
  sim::Renderer renderer_;
  frontend::FeatureTracker tracker_;
  std::vector<sim::RenderedView> views_;
  std::optional<segmentation::BoxChain> chain_;
  std::vector<segmentation::BoxEstimate> boxes_;
};

}  // namespace eval
}  // namespace vimot

#pragma once
// The simulator's messages through the processes' Node classes, offline and
// in one thread: what `vimot-sim` publishes (IMU, GROUND_TRUTH and FEATURES;
// with --render the images, true masks and true boxes instead of FEATURES),
// each message converted to the LCM struct the subscriber receives and back
// (common/process/lcm_conversions.h, image_conversion.h), in the
// simulator's order, as the LCM stack delivers it when every process keeps
// up. The estimator Node (VinsNode or TargetFilterNode, behind
// EstimatorInputs) gets the IMU, the ground truth and FEATURES; from pixels
// FEATURES come from a FeatureTrackerNode fed the images and the true boxes
// (as config/feature_tracker_sim.yaml: wait_for_box), or with a box chain
// the boxes of SegmenterNode -> MaskFilterNode (config/
// feature_tracker_segmented.yaml). The offline evaluators run this, so their
// figures are the LCM pipeline's by construction (docs/evaluation.md).

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>

#include "common/frontend/tracker_options.h"
#include "common/segmentation/box_chain.h"
#include "common/sim/renderer.h"
#include "common/sim/simulator.h"
#include "common/types/ground_truth.h"
#include "common/types/sensor_data.h"
#include "procs/feature_tracker/feature_tracker_node.h"
#include "procs/mask_filter/mask_filter_node.h"
#include "procs/segmenter/segmenter_node.h"

namespace vimot {
namespace eval {

/// The estimator Node's subscriptions (IMU, GROUND_TRUTH, FEATURES) and its
/// end of input.
struct EstimatorInputs {
  std::function<void(const ImuData&)> on_imu;
  std::function<void(const GroundTruth&)> on_ground_truth;
  std::function<void(const CameraFrame&)> on_frame;
  std::function<void()> flush;
};

class SimPipeline {
 public:
  /// Plays `sim` (which must outlive this) into `estimator`; `pixels` set:
  /// FEATURES from the rendered images through the feature tracker with
  /// these options on the simulator's calibrations; `box_chain` (with
  /// pixels): the target boxes from the segmenter and mask filter instead
  /// of the truth. Throws std::invalid_argument for a box chain without pixels.
  SimPipeline(sim::Simulator& sim, EstimatorInputs estimator,
              const std::optional<frontend::FeatureTrackerOptions>& pixels = std::nullopt,
              const std::optional<segmentation::BoxChainOptions>& box_chain = std::nullopt);
  ~SimPipeline();
  SimPipeline(const SimPipeline&) = delete;
  SimPipeline& operator=(const SimPipeline&) = delete;

  /// Plays every event, then flushes the Nodes (end of input), unless
  /// stop() was called from a callback: then it returns after that event.
  /// `progress` gets the fraction of the simulator's camera frames played.
  void run(const std::function<void(double)>& progress = {});
  void stop() { stopped_ = true; }
  bool stopped() const { return stopped_; }

  /// From pixels: the feature tracker Node (nullptr otherwise).
  const FeatureTrackerNode* tracker() const { return tracker_.get(); }

 private:
  void camera_frame(const CameraFrame& simulated);

  sim::Simulator& sim_;
  EstimatorInputs estimator_;
  std::unique_ptr<sim::Renderer> renderer_;
  std::unique_ptr<FeatureTrackerNode> tracker_;
  std::unique_ptr<SegmenterNode> segmenter_;
  std::unique_ptr<MaskFilterNode> mask_filter_;
  bool stopped_{false};
};

}  // namespace eval
}  // namespace vimot

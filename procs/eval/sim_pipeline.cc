#include "procs/eval/sim_pipeline.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "common/process/image_conversion.h"
#include "common/process/lcm_conversions.h"

namespace vimot {
namespace eval {

namespace {

// A pixel stage that cannot process its input would leave the estimator
// without frames: a clear error instead of a quietly worse run.
std::function<void(const NodeEvent&)> fail_on_error(const std::string& stage) {
  return [stage](const NodeEvent& e) {
    if (e.kind == NodeEvent::Kind::kError) throw std::runtime_error(stage + ": " + e.message);
  };
}

std::optional<frontend::Box> box_from(const std::optional<Eigen::Vector4d>& b) {
  if (!b) return std::nullopt;
  return frontend::Box{(*b)(0), (*b)(1), (*b)(2), (*b)(3)};
}

}  // namespace

SimPipeline::SimPipeline(sim::Simulator& sim, EstimatorInputs estimator,
                         const std::optional<frontend::FeatureTrackerOptions>& pixels,
                         const std::optional<segmentation::BoxChainOptions>& box_chain)
    : sim_(sim), estimator_(std::move(estimator)) {
  if (box_chain && !pixels) throw std::invalid_argument("SimPipeline: a box chain needs pixels");
  if (!pixels) return;
  const std::vector<CameraCalibration>& cameras = sim.cameras();
  renderer_ = std::make_unique<sim::Renderer>(sim);
  FeatureTrackerNodeOptions t;
  t.tracker = *pixels;
  t.cameras = cameras;
  t.wait_for_box = true;  // every image has its box (true or segmented), as the shipped configs say
  // The segmenter's box may come a few frames late over LCM
  // (feature_tracker_segmented.yaml); here it always comes with its image.
  t.box_wait_frames = box_chain ? 3 : 1;
  tracker_ = std::make_unique<FeatureTrackerNode>(
      t, [this](const CameraFrame& f) { estimator_.on_frame(from_lcm(to_lcm(f))); },
      fail_on_error("feature tracker"));
  if (!box_chain) return;
  SegmenterNodeOptions s;
  static_cast<segmentation::SegmenterOptions&>(s) = box_chain->segmenter;
  s.cameras = static_cast<int>(cameras.size());
  s.image_width = cameras.front().width;
  s.image_height = cameras.front().height;
  MaskFilterNodeOptions m;
  m.filter = box_chain->filter;
  for (const CameraCalibration& c : cameras) m.resolution.push_back({c.width, c.height});
  mask_filter_ = std::make_unique<MaskFilterNode>(
      m,
      [this](const CameraBox& b) {
        // TARGET_BOX as the feature tracker takes it (box_of).
        tracker_->on_box(b.camera_id, b.estimate.utime, box_from(segmentation::tracker_box(b.estimate)));
      },
      fail_on_error("mask filter"));
  segmenter_ = std::make_unique<SegmenterNode>(
      s,
      [this](int camera_id, int64_t utime, const cv::Mat& mask) {
        const mask_t msg = to_lcm_mask(mask, utime, camera_id);
        // TARGET_MASK goes to the feature tracker (target.use_mask) and the mask filter.
        tracker_->on_mask(msg.camera_id, msg.utime, mask_from_lcm(msg));
        mask_filter_->on_mask(msg.camera_id, msg.utime, msg.width, msg.height, msg.size, msg.data);
      },
      fail_on_error("segmenter"));
}

SimPipeline::~SimPipeline() = default;

void SimPipeline::camera_frame(const CameraFrame& simulated) {
  if (!renderer_) {
    estimator_.on_frame(from_lcm(to_lcm(simulated)));
    return;
  }
  // vimot-sim --render: per camera its image, true mask and true box.
  for (const sim::RenderedView& view : renderer_->render(simulated.utime)) {
    const cv::Mat image = grey_from_lcm_image(to_lcm_image(view.image, view.utime));
    tracker_->on_image(view.camera_id, view.utime, image);
    if (segmenter_) {
      if (segmenter_->uses_truth()) {
        const mask_t truth = to_lcm_mask(view.mask, view.utime, view.camera_id);
        segmenter_->on_true_mask(view.camera_id, view.utime, mask_from_lcm(truth));
      } else {
        segmenter_->on_image(view.camera_id, view.utime, image);
      }
    } else {
      // TARGET_MASK_TRUTH (target.use_mask), then TARGET_BOX_TRUTH: a
      // perfect detection when the target is visible.
      tracker_->on_mask(view.camera_id, view.utime, mask_from_lcm(to_lcm_mask(view.mask, view.utime, view.camera_id)));
      tracker_->on_box(view.camera_id, view.utime, view.visible ? box_from(view.box) : std::nullopt);
    }
  }
}

void SimPipeline::run(const std::function<void(double)>& progress) {
  const double frames_total = static_cast<double>(std::max<int64_t>(1, sim_.camera_frame_count()));
  int64_t frames = 0;
  while (!stopped_) {
    const std::optional<sim::SimEvent> ev = sim_.next();
    if (!ev) break;
    if (const auto* imu = std::get_if<ImuData>(&*ev)) {
      estimator_.on_imu(from_lcm(to_lcm(*imu)));
    } else if (const auto* gt = std::get_if<GroundTruth>(&*ev)) {
      estimator_.on_ground_truth(from_lcm(to_lcm(*gt)));
    } else {
      camera_frame(std::get<CameraFrame>(*ev));
      ++frames;
      if (progress) progress(static_cast<double>(frames) / frames_total);
    }
  }
  if (stopped_) return;
  if (tracker_) tracker_->flush();
  if (!stopped_) estimator_.flush();
}

}  // namespace eval
}  // namespace vimot

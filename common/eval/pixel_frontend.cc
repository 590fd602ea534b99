#include "common/eval/pixel_frontend.h"

#include <vector>

namespace vimot {
namespace eval {

PixelFrontEnd::PixelFrontEnd(const sim::Simulator& sim, const frontend::FeatureTrackerOptions& options,
                             const std::optional<segmentation::BoxChainOptions>& boxes)
    : renderer_(sim), tracker_(options, sim.cameras()) {
  if (boxes) chain_.emplace(*boxes, static_cast<int>(sim.cameras().size()));
}

CameraFrame PixelFrontEnd::frame(int64_t utime) {
  views_ = renderer_.render(utime);
  const std::vector<sim::RenderedView>& views = views_;
  boxes_.clear();
  // The mask the node pairs with each image under target.use_mask:
  // TARGET_MASK_TRUTH (the view's) or the segmenter's TARGET_MASK.
  std::vector<cv::Mat> masks;
  for (std::size_t cam = 0; cam < views.size(); ++cam) {
    if (chain_) {
      boxes_.push_back(chain_->process(static_cast<int>(cam), utime, views[cam].image, views[cam].mask));
      masks.push_back(chain_->last_mask().clone());  // last_mask() is the chain's own buffer
    } else {
      masks.push_back(views[cam].mask);
    }
  }
  // Truth: a box only where the target is visible (the feature tracker node
  // takes TARGET_BOX_TRUTH's filtered box only when filtered_valid =
  // visible). Box chain: what the node takes from TARGET_BOX.
  auto box_of = [&](std::size_t cam) -> std::optional<frontend::Box> {
    if (cam >= views.size()) return std::nullopt;
    std::optional<Eigen::Vector4d> b;
    if (chain_) {
      b = segmentation::tracker_box(boxes_[cam]);
    } else if (views[cam].visible) {
      b = views[cam].box;
    }
    if (!b) return std::nullopt;
    return frontend::Box{(*b)(0), (*b)(1), (*b)(2), (*b)(3)};
  };
  const bool stereo = views.size() > 1;
  return tracker_.track(utime, views[0].image, stereo ? views[1].image : cv::Mat(), box_of(0), box_of(1), masks[0],
                        stereo ? masks[1] : cv::Mat());
}

}  // namespace eval
}  // namespace vimot

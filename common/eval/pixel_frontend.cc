#include "common/eval/pixel_frontend.h"

#include <vector>

namespace vimot {
namespace eval {

PixelFrontEnd::PixelFrontEnd(const sim::Simulator& sim, const frontend::FeatureTrackerOptions& options)
    : renderer_(sim), tracker_(options, sim.cameras()) {}

CameraFrame PixelFrontEnd::frame(int64_t utime) {
  views_ = renderer_.render(utime);
  const std::vector<sim::RenderedView>& views = views_;
  // A box only where the target is visible: the feature tracker node takes
  // TARGET_BOX_TRUTH's filtered box only when filtered_valid (= visible).
  auto box_of = [&views](std::size_t cam) -> std::optional<frontend::Box> {
    if (cam >= views.size() || !views[cam].visible) return std::nullopt;
    const auto& b = views[cam].box;
    return frontend::Box{b(0), b(1), b(2), b(3)};
  };
  const cv::Mat right = views.size() > 1 ? views[1].image : cv::Mat();
  return tracker_.track(utime, views[0].image, right, box_of(0), box_of(1));
}

}  // namespace eval
}  // namespace vimot

#include "common/eval/box_eval.h"

#include <algorithm>
#include <map>
#include <utility>

#include "common/segmentation/blob.h"

namespace vimot {
namespace eval {

std::vector<BoxCameraFigures> evaluate_boxes(const std::vector<CameraTargetBox>& boxes,
                                             const std::vector<CameraTargetBox>& truths) {
  std::vector<BoxCameraFigures> f(2);
  std::map<std::pair<int, int64_t>, const CameraTargetBox*> by_key;
  for (const CameraTargetBox& b : boxes) {
    if (b.camera_id < 0 || b.camera_id > 1) continue;
    if (!by_key.emplace(std::make_pair(b.camera_id, b.utime), &b).second) continue;
    BoxCameraFigures& c = f[static_cast<std::size_t>(b.camera_id)];
    ++c.boxes;
    c.filtered_valid += b.filtered_valid ? 1 : 0;
    c.raw_valid += b.raw_valid ? 1 : 0;
    c.max_coasted = std::max(c.max_coasted, b.frames_since_raw);
  }
  std::vector<double> iou_sum(2, 0.0);
  for (const CameraTargetBox& t : truths) {
    if (t.camera_id < 0 || t.camera_id > 1) continue;
    BoxCameraFigures& c = f[static_cast<std::size_t>(t.camera_id)];
    ++c.truth_frames;
    const bool visible = t.filtered_valid;
    c.truth_visible += visible ? 1 : 0;
    const auto it = by_key.find({t.camera_id, t.utime});
    if (it == by_key.end()) {
      ++c.missing;
      continue;
    }
    const CameraTargetBox& b = *it->second;
    if (!b.filtered_valid) continue;
    if (!visible) {
      ++c.false_boxes;
      continue;
    }
    const double iou = segmentation::box_iou(b.filtered_box, t.filtered_box);
    c.min_iou = c.kept == 0 ? iou : std::min(c.min_iou, iou);
    ++c.kept;
    iou_sum[static_cast<std::size_t>(t.camera_id)] += iou;
    c.low_iou += iou < 0.5 ? 1 : 0;
  }
  for (std::size_t k = 0; k < f.size(); ++k) {
    if (f[k].kept > 0) f[k].mean_iou = iou_sum[k] / static_cast<double>(f[k].kept);
  }
  return f;
}

}  // namespace eval
}  // namespace vimot

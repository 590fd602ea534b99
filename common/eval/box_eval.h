#pragma once
// The target box of a run (TARGET_BOX of vimot-mask-filter, or the offline
// box chain) against the rendered simulator's true box of the same image
// (TARGET_BOX_TRUTH): is the target kept, and how well does the box fit.
// No LCM here (vimot-log-eval reads the log). docs/segmented_pipeline.md.

#include <cstdint>
#include <vector>

#include "common/types/target_box.h"

namespace vimot {
namespace eval {

struct BoxCameraFigures {
  int64_t truth_frames{0};   // true boxes of this camera (one per image)
  int64_t truth_visible{0};  // ... with the target in the image
  int64_t boxes{0};          // estimated boxes
  int64_t missing{0};        // true boxes without an estimated one at their utime (lost or never made)
  int64_t filtered_valid{0}; // estimated boxes with a valid filtered box
  int64_t raw_valid{0};      // ... with a detection
  int64_t kept{0};           // target visible and a valid filtered box
  int64_t false_boxes{0};    // target not visible, yet a valid filtered box
  int64_t low_iou{0};        // kept, but IoU of the filtered box with the true one < 0.5
  double mean_iou{0.0};      // of the filtered box with the true one, over kept
  double min_iou{0.0};
  int max_coasted{0};        // longest frames_since_raw
};

/// Per camera (index = camera id, 0 and 1), matched on (utime, camera).
/// A second box of the same camera and utime is ignored.
std::vector<BoxCameraFigures> evaluate_boxes(const std::vector<CameraTargetBox>& boxes,
                                             const std::vector<CameraTargetBox>& truths);

}  // namespace eval
}  // namespace vimot

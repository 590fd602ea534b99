// evaluate_boxes (common/eval/box_eval.h) on hand-made boxes: matching on
// (utime, camera), kept / missing / false counts, and the IoU against
// hand-computed values.
#include <catch2/catch.hpp>

#include "common/eval/box_eval.h"

using namespace vimot;

namespace {

CameraTargetBox box(int64_t utime, int camera, bool valid, double x, double y, double w, double h) {
  CameraTargetBox b;
  b.utime = utime;
  b.camera_id = camera;
  b.raw_valid = b.filtered_valid = valid;
  b.raw_box = b.filtered_box = Eigen::Vector4d(x, y, w, h);
  return b;
}

}  // namespace

TEST_CASE("box figures: kept, missing, false boxes and IoU per camera") {
  const std::vector<CameraTargetBox> truths = {
      box(100, 0, true, 0, 0, 10, 10),  box(200, 0, true, 0, 0, 10, 10), box(300, 0, true, 0, 0, 10, 10),
      box(400, 0, false, 0, 0, 0, 0),   box(100, 1, true, 0, 0, 10, 10),
  };
  CameraTargetBox coasted = box(200, 0, false, 0, 0, 0, 0);  // filtered box valid, no detection
  coasted.filtered_valid = true;
  coasted.filtered_box = Eigen::Vector4d(5, 0, 10, 10);  // overlap 5x10 = 50, union 150
  coasted.frames_since_raw = 3;
  const std::vector<CameraTargetBox> boxes = {
      box(100, 0, true, 0, 0, 10, 10),   // identical: IoU 1
      coasted,
      box(300, 0, false, 0, 0, 0, 0),    // target visible, no box
      box(400, 0, true, 50, 50, 4, 4),   // a box without the target
      box(100, 0, true, 90, 90, 1, 1),   // a second box at the same utime: ignored
      // camera 1 has no box at 100: missing
  };
  const std::vector<eval::BoxCameraFigures> f = eval::evaluate_boxes(boxes, truths);
  REQUIRE(f.size() == 2);
  CHECK(f[0].truth_frames == 4);
  CHECK(f[0].truth_visible == 3);
  CHECK(f[0].boxes == 4);
  CHECK(f[0].missing == 0);
  CHECK(f[0].filtered_valid == 3);
  CHECK(f[0].raw_valid == 2);
  CHECK(f[0].kept == 2);
  CHECK(f[0].false_boxes == 1);
  CHECK(f[0].max_coasted == 3);
  CHECK(f[0].min_iou == Approx(1.0 / 3.0));
  CHECK(f[0].mean_iou == Approx((1.0 + 1.0 / 3.0) / 2.0));
  CHECK(f[0].low_iou == 1);
  CHECK(f[1].truth_frames == 1);
  CHECK(f[1].missing == 1);
  CHECK(f[1].kept == 0);
}

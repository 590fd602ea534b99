#pragma once
// A camera's target box as TARGET_BOX (vimot-mask-filter) and
// TARGET_BOX_TRUTH (vimot-sim --render) carry it
// (lcmtypes/vimot_target_box_t.lcm), for offline tools. No LCM here.

#include <Eigen/Core>
#include <cstdint>

namespace vimot {

struct CameraTargetBox {
  int64_t utime{0};  // µs, the image's
  int camera_id{0};  // 0 left, 1 right
  bool raw_valid{false};
  Eigen::Vector4d raw_box{Eigen::Vector4d::Zero()};  // px, [x_min, y_min, width, height]
  bool filtered_valid{false};
  Eigen::Vector4d filtered_box{Eigen::Vector4d::Zero()};  // px
  int frames_since_raw{0};  // frames coasted since the last fused detection
};

}  // namespace vimot

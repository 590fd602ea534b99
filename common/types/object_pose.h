#pragma once
// Up-to-scale object pose of the monocular object tracker (scale paper,
// Sec. III), the payload of OBJECT_POSE_UPTOSCALE. No LCM here.

#include <Eigen/Core>
#include <cstdint>

namespace vimot {

struct ObjectPoseEstimate {
  int64_t utime{0};                                    // µs, of the camera frame
  bool valid{false};                                   // pose fields meaningless if false
  Eigen::Vector4d q_OtoC{0.0, 0.0, 0.0, 1.0};          // JPL [qx qy qz qw] of R_OtoC
  Eigen::Vector3d pbar_OinC{Eigen::Vector3d::Zero()};  // up to scale: p_OinC = s * pbar_OinC
  int num_features{0};                                 // BA features seen in this frame
  double reprojection_rms_px{0.0};                     // px, of those features in this frame
  int64_t track_id{0};                                 // +1 at each (re)initialisation; 0 before the first
};

}  // namespace vimot

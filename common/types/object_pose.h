#pragma once
// The object tracker's up-to-scale object pose (OBJECT_POSE_UPTOSCALE,
// lcmtypes/vimot_object_pose_t.lcm). No LCM here.

#include <Eigen/Core>
#include <cstdint>

namespace vimot {

struct ObjectPoseUpToScale {
  int64_t utime{0};  // µs, the camera frame the pose refers to
  /// False when the tracker failed on this frame (tracking lost): the pose
  /// fields are meaningless then.
  bool valid{false};
  Eigen::Vector4d q_OtoC{0.0, 0.0, 0.0, 1.0};          // JPL [qx qy qz qw]
  Eigen::Vector3d pbar_OinC{Eigen::Vector3d::Zero()};  // tracker unit (metric = s * pbar_OinC)
  int num_features{0};
  double reprojection_rms{0.0};  // px
};

}  // namespace vimot

#pragma once
// The fixed transform between a target filter's target frame and the true
// one, for evaluating a filter that defines its own target frame (the target
// filter's start from its features, common/target/target_filter.h). Both
// frames are fixed to the same rigid body, so one transform X, taken at the
// filter's first estimate, relates them for the whole run; the truth of the
// filter's frame is then the true target pose composed with X, and every
// error, RMSE and NEES is computed against that. The filter defines its
// frame relative to the robot at that time, so X is taken in the IMU frame:
// the first target-in-IMU error is zero by construction, and the first
// target-in-world error is the robot's own error at that time. A filter
// started from the truth has X = identity, and the truth is used unchanged
// (figures bit-identical to comparing with the truth directly). No LCM.

#include <Eigen/Core>
#include <string>

#include "common/types/ground_truth.h"

namespace vimot {
namespace eval {

/// The filter's target frame T' in the true target frame T:
/// R_TtoT' = quat_to_rot(q_TtoTest), p_T'inT = p_TestInT.
struct TargetFrameTransform {
  Eigen::Vector4d q_TtoTest{0.0, 0.0, 0.0, 1.0};  // JPL
  Eigen::Vector3d p_TestInT{Eigen::Vector3d::Zero()};

  bool is_identity() const;
  double angle_deg() const;  // rotation angle of R_TtoT'
  /// "angle X deg, offset [x y z] m (in T), q [qx qy qz qw]".
  std::string describe() const;
};

/// X from the truth (has_target) and the filter's estimate of its frame in
/// the IMU frame [q_ItoT', p_T'inI] at the same utime: T' = T ∘ X in I.
TargetFrameTransform target_frame_transform(const GroundTruth& truth, const Eigen::Vector4d& q_ItoT_est,
                                            const Eigen::Vector3d& p_TinI_est);

/// The truth of the filter's frame: q_GtoT, p_TinG, v_TinT, w_TinT of T ∘ X
/// (the velocities of the body point p_T'inT, in T'); `truth` itself when X
/// is the identity or the truth has no target.
GroundTruth in_target_frame(const GroundTruth& truth, const TargetFrameTransform& X);

}  // namespace eval
}  // namespace vimot

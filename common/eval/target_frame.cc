#include "common/eval/target_frame.h"

#include <cmath>
#include <cstdio>

#include "common/eval/metrics.h"
#include "common/math/quat.h"

namespace vimot {
namespace eval {

bool TargetFrameTransform::is_identity() const {
  return q_TtoTest == Eigen::Vector4d(0.0, 0.0, 0.0, 1.0) && p_TestInT.isZero(0.0);
}

double TargetFrameTransform::angle_deg() const {
  return orientation_error(q_TtoTest, Eigen::Vector4d(0.0, 0.0, 0.0, 1.0)).norm() * 180.0 / M_PI;
}

std::string TargetFrameTransform::describe() const {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "angle %.3f deg, offset [%.4f %.4f %.4f] m (in T), q [%.6f %.6f %.6f %.6f]",
                angle_deg(), p_TestInT.x(), p_TestInT.y(), p_TestInT.z(), q_TtoTest(0), q_TtoTest(1), q_TtoTest(2),
                q_TtoTest(3));
  return buf;
}

TargetFrameTransform target_frame_transform(const GroundTruth& truth, const Eigen::Vector4d& q_ItoT_est,
                                            const Eigen::Vector3d& p_TinI_est) {
  const TargetInImu t = true_target_in_imu(truth);
  const Eigen::Matrix3d R_ItoT = quat_to_rot(t.q_ItoT);
  TargetFrameTransform X;
  X.q_TtoTest = rot_to_quat(quat_to_rot(q_ItoT_est) * R_ItoT.transpose());
  X.p_TestInT = R_ItoT * (p_TinI_est - t.p_TinI);
  return X;
}

GroundTruth in_target_frame(const GroundTruth& truth, const TargetFrameTransform& X) {
  if (!truth.has_target || X.is_identity()) return truth;
  const Eigen::Matrix3d R_X = quat_to_rot(X.q_TtoTest);
  const Eigen::Matrix3d R_GtoT = quat_to_rot(truth.q_GtoT);
  GroundTruth out = truth;
  out.q_GtoT = rot_to_quat(R_X * R_GtoT);
  out.p_TinG = truth.p_TinG + R_GtoT.transpose() * X.p_TestInT;
  out.v_TinT = R_X * (truth.v_TinT + truth.w_TinT.cross(X.p_TestInT));
  out.w_TinT = R_X * truth.w_TinT;
  return out;
}

}  // namespace eval
}  // namespace vimot

#include "common/target/target_conversion.h"

#include "common/math/quat.h"

namespace vimot {
namespace target {

TargetValue local_to_global(const PoseValue& imu_pose, const TargetValue& x_local, Matrix12x6d* J_pose,
                            Matrix12d* J_target) {
  const Eigen::Matrix3d R_GtoI = imu_pose.R();
  const Eigen::Matrix3d R_ItoT = x_local.R_RtoT();
  TargetValue g;
  g.q_RtoT = rot_to_quat(R_ItoT * R_GtoI);
  g.p_TinR = imu_pose.p + R_GtoI.transpose() * x_local.p_TinR;
  g.v_TinT = x_local.v_TinT;
  g.w_TinT = x_local.w_TinT;
  if (J_pose) {
    J_pose->setZero();
    J_pose->block<3, 3>(0, 0) = R_ItoT;
    J_pose->block<3, 3>(3, 0) = -R_GtoI.transpose() * skew(x_local.p_TinR);
    J_pose->block<3, 3>(3, 3) = Eigen::Matrix3d::Identity();
  }
  if (J_target) {
    J_target->setIdentity();
    J_target->block<3, 3>(3, 3) = R_GtoI.transpose();
  }
  return g;
}

TargetValue global_to_local(const PoseValue& imu_pose, const TargetValue& x_global, Matrix12x6d* J_pose,
                            Matrix12d* J_target) {
  const Eigen::Matrix3d R_GtoI = imu_pose.R();
  const Eigen::Matrix3d R_ItoT = x_global.R_RtoT() * R_GtoI.transpose();
  TargetValue l;
  l.q_RtoT = rot_to_quat(R_ItoT);
  l.p_TinR = R_GtoI * (x_global.p_TinR - imu_pose.p);
  l.v_TinT = x_global.v_TinT;
  l.w_TinT = x_global.w_TinT;
  if (J_pose) {
    J_pose->setZero();
    J_pose->block<3, 3>(0, 0) = -R_ItoT;
    J_pose->block<3, 3>(3, 0) = skew(l.p_TinR);
    J_pose->block<3, 3>(3, 3) = -R_GtoI;
  }
  if (J_target) {
    J_target->setIdentity();
    J_target->block<3, 3>(3, 3) = R_GtoI;
  }
  return l;
}

namespace {
Matrix12d joint_covariance(const Matrix12x6d& Jp, const Matrix12d& Jt, const Eigen::Matrix<double, 18, 18>& P) {
  Eigen::Matrix<double, 12, 18> J;
  J << Jp, Jt;
  Matrix12d out = J * P * J.transpose();
  return 0.5 * (out + out.transpose());
}
}  // namespace

Matrix12d local_to_global_covariance(const PoseValue& imu_pose, const TargetValue& x_local,
                                     const Eigen::Matrix<double, 18, 18>& P_pose_target) {
  Matrix12x6d Jp;
  Matrix12d Jt;
  local_to_global(imu_pose, x_local, &Jp, &Jt);
  return joint_covariance(Jp, Jt, P_pose_target);
}

Matrix12d global_to_local_covariance(const PoseValue& imu_pose, const TargetValue& x_global,
                                     const Eigen::Matrix<double, 18, 18>& P_pose_target) {
  Matrix12x6d Jp;
  Matrix12d Jt;
  global_to_local(imu_pose, x_global, &Jp, &Jt);
  return joint_covariance(Jp, Jt, P_pose_target);
}

}  // namespace target
}  // namespace vimot

#include "common/target/target_measurement.h"

#include "common/math/quat.h"

namespace vimot {
namespace target {

Eigen::MatrixXd point_relinearization(TargetRepresentation representation, const Eigen::Matrix3d& R_ItoT,
                                      const Eigen::Vector3d& p_lin, const Eigen::Vector3d& p_new) {
  const bool global = representation == TargetRepresentation::kGlobal;
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, global ? 15 : 9);
  const Eigen::Matrix3d lever = skew(p_new - p_lin);
  J.leftCols<3>() = lever;
  if (global) J.middleCols<3>(6) = -lever * R_ItoT;
  J.rightCols<3>().setIdentity();
  return J;
}

Eigen::Vector3d target_point_in_camera(TargetRepresentation representation, const PoseValue& imu_pose,
                                       const PoseValue& target_pose, const Eigen::Vector3d& p_FinT,
                                       const CameraExtrinsics& cam) {
  const Eigen::Vector3d p_FinR = target_pose.R().transpose() * p_FinT + target_pose.p;
  if (representation == TargetRepresentation::kLocal) return cam.R_ItoC * p_FinR + cam.p_IinC;
  return cam.R_ItoC * (imu_pose.R() * (p_FinR - imu_pose.p)) + cam.p_IinC;
}

TargetPointPrediction predict_target_point(TargetRepresentation representation, const PoseValue& imu_pose,
                                           const PoseValue& target_pose, const Eigen::Vector3d& p_FinT,
                                           const CameraExtrinsics& cam, double min_depth) {
  TargetPointPrediction out;
  const Eigen::Matrix3d R_RtoT = target_pose.R();
  const Eigen::Vector3d p_FinR = R_RtoT.transpose() * p_FinT + target_pose.p;  // point in R (G or I)

  // dp_FinC / d(point in R) and the IMU part.
  Eigen::Matrix3d R_RtoC;
  Eigen::Matrix<double, 3, 6> dpc_dimu = Eigen::Matrix<double, 3, 6>::Zero();
  if (representation == TargetRepresentation::kLocal) {
    R_RtoC = cam.R_ItoC;
    out.p_FinC = cam.R_ItoC * p_FinR + cam.p_IinC;
  } else {
    const Eigen::Matrix3d R_GtoI = imu_pose.R();
    R_RtoC = cam.R_ItoC * R_GtoI;
    const Eigen::Vector3d p_FinI = R_GtoI * (p_FinR - imu_pose.p);
    out.p_FinC = cam.R_ItoC * p_FinI + cam.p_IinC;
    dpc_dimu.leftCols<3>() = cam.R_ItoC * skew(p_FinI);
    dpc_dimu.rightCols<3>() = -R_RtoC;
  }
  Eigen::Matrix<double, 3, 6> dpc_dtarget;
  dpc_dtarget.leftCols<3>() = -R_RtoC * R_RtoT.transpose() * skew(p_FinT);
  dpc_dtarget.rightCols<3>() = R_RtoC;
  const Eigen::Matrix3d dpc_dpoint = R_RtoC * R_RtoT.transpose();

  const Eigen::Vector3d& pc = out.p_FinC;
  out.valid = pc.z() > min_depth;
  out.z = pc.head<2>() / pc.z();
  Eigen::Matrix<double, 2, 3> dz;
  dz << 1.0 / pc.z(), 0.0, -pc.x() / (pc.z() * pc.z()), 0.0, 1.0 / pc.z(), -pc.y() / (pc.z() * pc.z());
  out.H_imu_pose = dz * dpc_dimu;
  out.H_target_pose = dz * dpc_dtarget;
  out.H_point = dz * dpc_dpoint;
  return out;
}

}  // namespace target
}  // namespace vimot

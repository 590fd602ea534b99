#include "common/estimator/measurement_model.h"

#include <stdexcept>
#include <string>

#include "common/math/quat.h"

namespace vimot {
namespace estimator {

CameraInfo CameraInfo::from_calibration(const CameraCalibration& calibration, double sigma_px) {
  if (!(sigma_px > 0.0)) {
    throw std::invalid_argument("CameraInfo: sigma_px must be positive, got " + std::to_string(sigma_px));
  }
  const double f = 0.5 * (calibration.intrinsics(0) + calibration.intrinsics(1));
  if (!(f > 0.0)) throw std::invalid_argument("CameraInfo: focal length must be positive, got " + std::to_string(f));
  CameraInfo info;
  info.R_ItoC = calibration.R_ItoC;
  info.p_IinC = calibration.p_IinC;
  info.sigma_normalized = sigma_px / f;
  info.sigma_px = sigma_px;
  info.model = std::make_shared<const CameraModel>(calibration);
  return info;
}

Eigen::Matrix<double, 2, 3> project_jacobian(const Eigen::Vector3d& p) {
  const double iz = 1.0 / p.z();
  Eigen::Matrix<double, 2, 3> J;
  J << iz, 0.0, -p.x() * iz * iz, 0.0, iz, -p.y() * iz * iz;
  return J;
}

Eigen::Vector3d point_in_camera(const Eigen::Matrix3d& R_GtoI, const Eigen::Vector3d& p_IinG,
                                const Eigen::Vector3d& p_FinG, const CameraInfo& cam) {
  return cam.R_ItoC * (R_GtoI * (p_FinG - p_IinG)) + cam.p_IinC;
}

Eigen::Vector2d global_point_measurement(const Eigen::Matrix3d& R_GtoI, const Eigen::Vector3d& p_IinG,
                                         const Eigen::Vector3d& p_FinG, const CameraInfo& cam,
                                         Eigen::Matrix<double, 2, 6>* H_pose, Eigen::Matrix<double, 2, 3>* H_f) {
  const Eigen::Vector3d p_FinI = R_GtoI * (p_FinG - p_IinG);
  const Eigen::Vector3d p_FinC = cam.R_ItoC * p_FinI + cam.p_IinC;
  if (H_pose || H_f) {
    const Eigen::Matrix<double, 2, 3> Hp = project_jacobian(p_FinC) * cam.R_ItoC;
    if (H_pose) {
      H_pose->leftCols<3>() = Hp * skew(p_FinI);
      H_pose->rightCols<3>() = -Hp * R_GtoI;
    }
    if (H_f) *H_f = Hp * R_GtoI;
  }
  return project(p_FinC);
}

Eigen::Vector3d anchored_to_global(const Eigen::Vector3d& lambda, const Eigen::Matrix3d& R_GtoA,
                                   const Eigen::Vector3d& p_AinG, const CameraInfo& anchor_cam,
                                   Eigen::Matrix3d* dpf_dlambda, Eigen::Matrix<double, 3, 6>* dpf_danchor) {
  const double a = lambda(0), b = lambda(1), rho = lambda(2);
  const Eigen::Vector3d p_FinCa(a / rho, b / rho, 1.0 / rho);
  const Eigen::Vector3d p_FinA = anchor_cam.R_ItoC.transpose() * (p_FinCa - anchor_cam.p_IinC);
  if (dpf_dlambda) {
    Eigen::Matrix3d dpc;
    dpc << 1.0 / rho, 0.0, -a / (rho * rho), 0.0, 1.0 / rho, -b / (rho * rho), 0.0, 0.0, -1.0 / (rho * rho);
    *dpf_dlambda = R_GtoA.transpose() * anchor_cam.R_ItoC.transpose() * dpc;
  }
  if (dpf_danchor) {
    dpf_danchor->leftCols<3>() = -R_GtoA.transpose() * skew(p_FinA);
    dpf_danchor->rightCols<3>() = Eigen::Matrix3d::Identity();
  }
  return p_AinG + R_GtoA.transpose() * p_FinA;
}

Eigen::Vector3d global_to_anchored(const Eigen::Vector3d& p_FinG, const Eigen::Matrix3d& R_GtoA,
                                   const Eigen::Vector3d& p_AinG, const CameraInfo& anchor_cam) {
  return global_to_anchored(p_FinG, R_GtoA, p_AinG, anchor_cam, nullptr, nullptr);
}

Eigen::Vector3d global_to_anchored(const Eigen::Vector3d& p_FinG, const Eigen::Matrix3d& R_GtoA,
                                   const Eigen::Vector3d& p_AinG, const CameraInfo& anchor_cam,
                                   Eigen::Matrix3d* dl_dpf, Eigen::Matrix<double, 3, 6>* dl_danchor) {
  const Eigen::Vector3d p_FinA = R_GtoA * (p_FinG - p_AinG);
  const Eigen::Vector3d p_FinCa = anchor_cam.R_ItoC * p_FinA + anchor_cam.p_IinC;
  const double iz = 1.0 / p_FinCa.z();
  if (dl_dpf || dl_danchor) {
    Eigen::Matrix3d dl_dpc;
    dl_dpc << iz, 0.0, -p_FinCa.x() * iz * iz, 0.0, iz, -p_FinCa.y() * iz * iz, 0.0, 0.0, -iz * iz;
    const Eigen::Matrix3d A = dl_dpc * anchor_cam.R_ItoC;
    if (dl_dpf) *dl_dpf = A * R_GtoA;
    if (dl_danchor) {
      dl_danchor->leftCols<3>() = A * skew(p_FinA);
      dl_danchor->rightCols<3>() = -A * R_GtoA;
    }
  }
  return Eigen::Vector3d(p_FinCa.x() * iz, p_FinCa.y() * iz, iz);
}

Eigen::Vector3d change_anchor(const Eigen::Vector3d& lambda_A, const Eigen::Matrix3d& R_GtoA,
                              const Eigen::Vector3d& p_AinG, const CameraInfo& cam_a, const Eigen::Matrix3d& R_GtoB,
                              const Eigen::Vector3d& p_BinG, const CameraInfo& cam_b,
                              Eigen::Matrix<double, 3, 15>* J) {
  Eigen::Matrix3d F_l, G_f;
  Eigen::Matrix<double, 3, 6> F_a, G_b;
  const Eigen::Vector3d p_FinG =
      anchored_to_global(lambda_A, R_GtoA, p_AinG, cam_a, J ? &F_l : nullptr, J ? &F_a : nullptr);
  const Eigen::Vector3d lambda_B =
      global_to_anchored(p_FinG, R_GtoB, p_BinG, cam_b, J ? &G_f : nullptr, J ? &G_b : nullptr);
  if (J) {
    J->leftCols<3>() = G_f * F_l;
    J->middleCols<6>(3) = G_f * F_a;
    J->rightCols<6>() = G_b;
  }
  return lambda_B;
}

}  // namespace estimator
}  // namespace vimot

#include "common/target/target_types.h"

#include <cmath>

#include "common/math/quat.h"

namespace vimot {
namespace target {

const char* to_string(TargetRepresentation representation) {
  switch (representation) {
    case TargetRepresentation::kGlobal: return "global";
    case TargetRepresentation::kLocal: return "local";
  }
  return "unknown";
}

Eigen::Matrix3d PoseValue::R() const { return quat_to_rot(q); }

PoseValue imu_pose(const estimator::ImuValue& imu) { return PoseValue{imu.q_GtoI, imu.p_IinG}; }

Eigen::Matrix3d TargetValue::R_RtoT() const { return quat_to_rot(q_RtoT); }

Eigen::Matrix<double, 13, 1> TargetValue::to_vector() const {
  Eigen::Matrix<double, 13, 1> x;
  x << q_RtoT, p_TinR, v_TinT, w_TinT;
  return x;
}

TargetValue TargetValue::from_vector(const Eigen::Matrix<double, 13, 1>& x) {
  TargetValue t;
  t.q_RtoT = x.segment<4>(0);
  t.p_TinR = x.segment<3>(4);
  t.v_TinT = x.segment<3>(7);
  t.w_TinT = x.segment<3>(10);
  return t;
}

TargetValue boxplus(const TargetValue& x, const Vector12d& dx) {
  TargetValue y;
  y.q_RtoT = quat_boxplus(x.q_RtoT, dx.segment<3>(0));
  y.p_TinR = x.p_TinR + dx.segment<3>(3);
  y.v_TinT = x.v_TinT + dx.segment<3>(6);
  y.w_TinT = x.w_TinT + dx.segment<3>(9);
  return y;
}

Vector12d boxminus(const TargetValue& y, const TargetValue& x) {
  Vector12d d;
  d.segment<3>(0) = -log_so3(y.R_RtoT() * x.R_RtoT().transpose());
  d.segment<3>(3) = y.p_TinR - x.p_TinR;
  d.segment<3>(6) = y.v_TinT - x.v_TinT;
  d.segment<3>(9) = y.w_TinT - x.w_TinT;
  return d;
}

PoseValue boxplus(const PoseValue& x, const Vector6d& dx) {
  return PoseValue{quat_boxplus(x.q, dx.head<3>()), x.p + dx.tail<3>()};
}

Vector6d boxminus(const PoseValue& y, const PoseValue& x) {
  Vector6d d;
  d.head<3>() = -log_so3(y.R() * x.R().transpose());
  d.tail<3>() = y.p - x.p;
  return d;
}

TargetNoise TargetNoise::isotropic(double sigma_v, double sigma_w) {
  TargetNoise n;
  n.sigma_v = Eigen::Vector3d::Constant(sigma_v);
  n.sigma_w = Eigen::Vector3d::Constant(sigma_w);
  return n;
}

TargetNoise TargetNoise::planar(double sigma_v_xy, double sigma_w_z) {
  TargetNoise n;
  n.sigma_v = Eigen::Vector3d(sigma_v_xy, sigma_v_xy, 0.0);
  n.sigma_w = Eigen::Vector3d(0.0, 0.0, sigma_w_z);
  return n;
}

Matrix6d TargetNoise::Qc() const {
  Vector6d d;
  d << sigma_v.cwiseAbs2(), sigma_w.cwiseAbs2();
  return d.asDiagonal();
}

bool TargetNoise::valid() const {
  return sigma_v.allFinite() && sigma_w.allFinite() && (sigma_v.array() >= 0.0).all() &&
         (sigma_w.array() >= 0.0).all();
}

}  // namespace target
}  // namespace vimot

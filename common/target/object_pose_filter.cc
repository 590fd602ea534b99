#include "common/target/object_pose_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Cholesky>

#include "common/estimator/chi_square.h"
#include "common/math/quat.h"

namespace vimot {
namespace target {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("ObjectPoseFilterOptions: " + what);
}

bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

void ObjectPoseFilterOptions::validate() const {
  require(noise.valid(), "noise densities must be finite and >= 0");
  require(finite_positive(k_lateral), "k_lateral must be finite and > 0");
  require(finite_positive(k_depth), "k_depth must be finite and > 0");
  require(sigma_theta_C.allFinite() && (sigma_theta_C.array() > 0.0).all(), "sigma_theta_C must be finite and > 0");
  require(finite_positive(init_sigma_v), "init_sigma_v must be finite and > 0");
  require(finite_positive(init_sigma_w), "init_sigma_w must be finite and > 0");
  require(finite_positive(chi2_multiplier), "chi2_multiplier must be finite and > 0");
  require(max_consecutive_rejections >= 1, "max_consecutive_rejections must be >= 1");
  require(finite_positive(max_gap_s), "max_gap_s must be finite and > 0");
}

Matrix6d measurement_covariance(const ObjectPoseFilterOptions& o, const ObjectPoseMeasurement& z) {
  const double d = z.p_OinC.norm();
  const Eigen::Vector3d sigma_p_C(o.k_lateral * d, o.k_lateral * d, o.k_depth * d * d);
  const Eigen::Matrix3d R_CtoO = quat_to_rot(z.q_GtoO) * z.R_CtoG;
  Matrix6d R = Matrix6d::Zero();
  R.topLeftCorner<3, 3>() = R_CtoO * o.sigma_theta_C.cwiseAbs2().asDiagonal() * R_CtoO.transpose();
  R.bottomRightCorner<3, 3>() = z.R_CtoG * sigma_p_C.cwiseAbs2().asDiagonal() * z.R_CtoG.transpose();
  return R;
}

const char* to_string(ObjectFilterStatus status) {
  switch (status) {
    case ObjectFilterStatus::kInitialized: return "initialized";
    case ObjectFilterStatus::kUpdated: return "updated";
    case ObjectFilterStatus::kRejectedOutlier: return "rejected (chi2 gate)";
    case ObjectFilterStatus::kReinitialized: return "reinitialized";
    case ObjectFilterStatus::kRejectedTimeOrder: return "rejected (time not after the filter's)";
    case ObjectFilterStatus::kRejectedInvalid: return "rejected (non-finite or degenerate)";
  }
  return "unknown";
}

ObjectPoseFilter::ObjectPoseFilter(const ObjectPoseFilterOptions& options)
    : options_((options.validate(), options)) {}

void ObjectPoseFilter::reset() {
  initialized_ = false;
  utime_ = 0;
  x_ = TargetValue();
  P_.setZero();
  consecutive_rejections_ = 0;
  last_nis_ = 0.0;
}

void ObjectPoseFilter::initialize(const ObjectPoseMeasurement& z, const Matrix6d& R) {
  initialized_ = true;
  utime_ = z.utime;
  x_ = TargetValue();
  x_.q_RtoT = z.q_GtoO;
  x_.p_TinR = z.p_OinG;
  P_.setZero();
  P_.topLeftCorner<6, 6>() = R;
  P_.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * options_.init_sigma_v * options_.init_sigma_v;
  P_.block<3, 3>(9, 9) = Eigen::Matrix3d::Identity() * options_.init_sigma_w * options_.init_sigma_w;
  consecutive_rejections_ = 0;
}

ObjectFilterStatus ObjectPoseFilter::add(const ObjectPoseMeasurement& z_in) {
  if (!(z_in.q_GtoO.allFinite() && z_in.p_OinG.allFinite() && z_in.p_OinC.allFinite() && z_in.R_CtoG.allFinite()) ||
      z_in.q_GtoO.norm() == 0.0 || z_in.p_OinC.norm() == 0.0) {
    ++stats_.invalid;
    return ObjectFilterStatus::kRejectedInvalid;
  }
  if (initialized_ && z_in.utime <= utime_) {
    ++(z_in.utime == utime_ ? stats_.duplicates : stats_.backwards);
    return ObjectFilterStatus::kRejectedTimeOrder;
  }
  ObjectPoseMeasurement z = z_in;
  z.q_GtoO = quat_normalize(z.q_GtoO);
  const Matrix6d R = measurement_covariance(options_, z);
  if (!initialized_) {
    initialize(z, R);
    ++stats_.initializations;
    return ObjectFilterStatus::kInitialized;
  }
  // Integer µs difference first: large absolute utimes lose nothing.
  const double dt = static_cast<double>(z.utime - utime_) * 1e-6;
  if (dt > options_.max_gap_s) {
    initialize(z, R);
    ++stats_.gap_reinitializations;
    return ObjectFilterStatus::kReinitialized;
  }

  Matrix12d Phi, Q;
  TargetValue x_pred;
  propagate_global(x_, dt, options_.noise, &x_pred, &Phi, &Q);
  const Matrix12d P_pred = Phi * P_ * Phi.transpose() + Q;
  x_ = x_pred;
  P_ = 0.5 * (P_pred + P_pred.transpose());
  utime_ = z.utime;

  const Vector6d r = boxminus(PoseValue{z.q_GtoO, z.p_OinG}, x_.pose());
  const Matrix6d S = P_.topLeftCorner<6, 6>() + R;
  const Eigen::LLT<Matrix6d> llt(S);
  last_nis_ = r.dot(llt.solve(r));
  if (!(last_nis_ < options_.chi2_multiplier * estimator::chi2_95(6))) {
    ++stats_.outliers;
    if (++consecutive_rejections_ >= options_.max_consecutive_rejections) {
      initialize(z, R);
      ++stats_.reinitializations;
      return ObjectFilterStatus::kReinitialized;
    }
    return ObjectFilterStatus::kRejectedOutlier;
  }
  consecutive_rejections_ = 0;
  // K = P Hᵀ S⁻¹ with H = [I₆ 0]; Joseph form keeps P symmetric positive.
  const Matrix12x6d K = llt.solve(P_.leftCols<6>().transpose()).transpose();
  Matrix12d IKH = Matrix12d::Identity();
  IKH.leftCols<6>() -= K;
  x_ = boxplus(x_, K * r);
  const Matrix12d P_new = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  P_ = 0.5 * (P_new + P_new.transpose());
  ++stats_.updates;
  return ObjectFilterStatus::kUpdated;
}

TargetPrediction ObjectPoseFilter::predict(double horizon_s) const {
  return predict_global(x_, P_, horizon_s, options_.noise);
}

}  // namespace target
}  // namespace vimot

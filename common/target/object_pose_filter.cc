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
  require(std::isfinite(bias_sigma_theta) && bias_sigma_theta >= 0.0, "bias_sigma_theta must be finite and >= 0");
  require(std::isfinite(bias_sigma_position) && bias_sigma_position >= 0.0,
          "bias_sigma_position must be finite and >= 0");
  require(std::isfinite(scale_sigma) && scale_sigma >= 0.0, "scale_sigma must be finite and >= 0");
  require(std::isfinite(scale_random_walk) && scale_random_walk >= 0.0,
          "scale_random_walk must be finite and >= 0");
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
  b_.setZero();
  P_.setZero();
  held_scale_ = 1.0;
  consecutive_rejections_ = 0;
  last_nis_ = 0.0;
}

ObjectPoseFilter::Matrix6x7d ObjectPoseFilter::bias_jacobian(const PoseValue& pose, const Eigen::Vector3d& p_CinG) {
  Matrix6x7d H = Matrix6x7d::Zero();
  H.topLeftCorner<3, 3>().setIdentity();
  H.block<3, 3>(3, 3) = pose.R().transpose();  // R_OtoG
  H.block<3, 1>(3, 6) = pose.p - p_CinG;
  return H;
}

void ObjectPoseFilter::initialize(const ObjectPoseMeasurement& z, const Matrix6d& R) {
  initialized_ = true;
  utime_ = z.utime;
  x_ = TargetValue();
  x_.q_RtoT = z.q_GtoO;
  x_.p_TinR = z.p_OinG;
  b_.setZero();
  held_scale_ = z.scale;
  // pose = z − H_b b − n: Cov(pose) = R + H_b P_b H_bᵀ, Cov(pose, b) = −H_b P_b.
  Vector7d bias_var;
  bias_var << Eigen::Vector3d::Constant(options_.bias_sigma_theta * options_.bias_sigma_theta),
      Eigen::Vector3d::Constant(options_.bias_sigma_position * options_.bias_sigma_position),
      options_.scale_sigma * options_.scale_sigma;
  const Matrix6x7d H_b = bias_jacobian(PoseValue{z.q_GtoO, z.p_OinG}, z.p_OinG - z.R_CtoG * z.p_OinC);
  const Matrix6x7d P_pose_b = -H_b * bias_var.asDiagonal();
  P_.setZero();
  P_.topLeftCorner<6, 6>() = R - P_pose_b * H_b.transpose();
  P_.block<6, 7>(0, 12) = P_pose_b;
  P_.block<7, 6>(12, 0) = P_pose_b.transpose();
  P_.bottomRightCorner<7, 7>() = bias_var.asDiagonal();
  P_.block<3, 3>(6, 6) = Eigen::Matrix3d::Identity() * options_.init_sigma_v * options_.init_sigma_v;
  P_.block<3, 3>(9, 9) = Eigen::Matrix3d::Identity() * options_.init_sigma_w * options_.init_sigma_w;
  consecutive_rejections_ = 0;
}

ObjectFilterStatus ObjectPoseFilter::add(const ObjectPoseMeasurement& z_in) {
  if (!(z_in.q_GtoO.allFinite() && z_in.p_OinG.allFinite() && z_in.p_OinC.allFinite() && z_in.R_CtoG.allFinite()) ||
      z_in.q_GtoO.norm() == 0.0 || z_in.p_OinC.norm() == 0.0 || !finite_positive(z_in.scale)) {
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

  // A new held scale: ε' = ŝ_new/s − 1 = (1 + ε) ŝ_new/ŝ_old − 1, exactly.
  const double ratio = z.scale / held_scale_;
  if (ratio != 1.0) {
    b_(6) = (1.0 + b_(6)) * ratio - 1.0;
    P_.row(18) *= ratio;
    P_.col(18) *= ratio;
    held_scale_ = z.scale;
  }
  Matrix12d Phi, Q;
  TargetValue x_pred;
  propagate_global(x_, dt, options_.noise, &x_pred, &Phi, &Q);
  Matrix19d Phi_full = Matrix19d::Identity(), Q_full = Matrix19d::Zero();
  Phi_full.topLeftCorner<12, 12>() = Phi;
  Q_full.topLeftCorner<12, 12>() = Q;
  Q_full(18, 18) = options_.scale_random_walk * options_.scale_random_walk * dt;
  const Matrix19d P_pred = Phi_full * P_ * Phi_full.transpose() + Q_full;
  x_ = x_pred;
  P_ = 0.5 * (P_pred + P_pred.transpose());
  utime_ = z.utime;

  // Predicted pose: the state with the biases applied (first order in θ_b).
  Eigen::Matrix<double, 6, 19> H = Eigen::Matrix<double, 6, 19>::Zero();
  H.leftCols<6>().setIdentity();
  // At the state, not at the noisy pose: a scaled copy of the object's path
  // about the camera (ε) is as good a path, and Jacobians taken at the
  // noisy poses would pretend otherwise (spurious information on ε).
  H.rightCols<7>() = bias_jacobian(x_.pose(), z.p_OinG - z.R_CtoG * z.p_OinC);
  const Vector6d r = boxminus(PoseValue{z.q_GtoO, z.p_OinG}, x_.pose()) - H.rightCols<7>() * b_;
  const Matrix6d S = H * P_ * H.transpose() + R;
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
  // Joseph form keeps P symmetric positive.
  const Eigen::Matrix<double, 19, 6> K = llt.solve(H * P_).transpose();
  const Matrix19d IKH = Matrix19d::Identity() - K * H;
  const Eigen::Matrix<double, 19, 1> dx = K * r;
  x_ = boxplus(x_, Vector12d(dx.head<12>()));
  b_ += dx.tail<7>();
  const Matrix19d P_new = IKH * P_ * IKH.transpose() + K * R * K.transpose();
  P_ = 0.5 * (P_new + P_new.transpose());
  ++stats_.updates;
  return ObjectFilterStatus::kUpdated;
}

TargetPrediction ObjectPoseFilter::predict(double horizon_s) const {
  return predict_global(x_, covariance(), horizon_s, options_.noise);
}

}  // namespace target
}  // namespace vimot

#include "common/segmentation/box_kalman.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/estimator/chi_square.h"

namespace vimot::segmentation {

namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("box Kalman options: " + what);
}

bool finite_positive(double v) { return std::isfinite(v) && v > 0.0; }

// [cu, cv, w, h] of a box [x_min, y_min, w, h].
Eigen::Vector4d center_form(const Eigen::Vector4d& box) {
  return {box(0) + 0.5 * box(2), box(1) + 0.5 * box(3), box(2), box(3)};
}

// d[x_min, y_min, w, h] / d[cu, cv, w, h].
Eigen::Matrix4d box_jacobian() {
  Eigen::Matrix4d J = Eigen::Matrix4d::Identity();
  J(0, 2) = -0.5;
  J(1, 3) = -0.5;
  return J;
}

}  // namespace

void BoxKalmanOptions::validate() const {
  require(finite_positive(center_sigma_px), "center_sigma_px must be > 0");
  require(finite_positive(size_sigma_px), "size_sigma_px must be > 0");
  require(std::isfinite(center_accel_noise) && center_accel_noise >= 0.0, "center_accel_noise must be >= 0");
  require(std::isfinite(size_accel_noise) && size_accel_noise >= 0.0, "size_accel_noise must be >= 0");
  require(finite_positive(init_center_velocity_sigma), "init_center_velocity_sigma must be > 0");
  require(finite_positive(init_size_velocity_sigma), "init_size_velocity_sigma must be > 0");
  require(gate_probability > 0.0 && gate_probability < 1.0, "gate_probability must be in (0, 1)");
  require(max_consecutive_rejections >= 1, "max_consecutive_rejections must be >= 1");
  require(finite_positive(max_coast_s), "max_coast_s must be > 0");
}

BoxKalmanFilter::BoxKalmanFilter(const BoxKalmanOptions& options) : options_(options) {
  options_.validate();
  gate_ = estimator::chi2_quantile(options_.gate_probability, 4);
}

void BoxKalmanFilter::initialise(int64_t utime, const Eigen::Vector4d& box) {
  x_.setZero();
  x_.head<4>() = center_form(box);
  P_.setZero();
  const double rc = options_.center_sigma_px * options_.center_sigma_px;
  const double rs = options_.size_sigma_px * options_.size_sigma_px;
  const double vc = options_.init_center_velocity_sigma * options_.init_center_velocity_sigma;
  const double vs = options_.init_size_velocity_sigma * options_.init_size_velocity_sigma;
  P_.diagonal() << rc, rc, rs, rs, vc, vc, vs, vs;
  valid_ = true;
  last_fused_utime_ = utime;
  frames_since_fused_ = 0;
  consecutive_rejections_ = 0;
}

void BoxKalmanFilter::predict(double dt) {
  // Constant velocity per axis: F = [[1, dt], [0, 1]]; white acceleration of
  // density q gives Q = q [[dt³/3, dt²/2], [dt²/2, dt]].
  Matrix8d F = Matrix8d::Identity();
  F.topRightCorner<4, 4>() = dt * Eigen::Matrix4d::Identity();
  x_ = F * x_;
  Matrix8d Q = Matrix8d::Zero();
  for (int i = 0; i < 4; ++i) {
    const double a = i < 2 ? options_.center_accel_noise : options_.size_accel_noise;
    const double q = a * a;
    Q(i, i) = q * dt * dt * dt / 3.0;
    Q(i, i + 4) = Q(i + 4, i) = q * dt * dt / 2.0;
    Q(i + 4, i + 4) = q * dt;
  }
  P_ = F * P_ * F.transpose() + Q;
}

BoxKalmanFilter::Outcome BoxKalmanFilter::step(int64_t utime, const Eigen::Vector4d* box) {
  if (has_time_ && utime <= last_utime_) {
    throw std::invalid_argument("box Kalman filter: utime " + std::to_string(utime) + " is not after the last (" +
                                std::to_string(last_utime_) + ")");
  }
  if (box != nullptr && !box->allFinite()) throw std::invalid_argument("box Kalman filter: box is not finite");
  const double dt = has_time_ ? 1e-6 * static_cast<double>(utime - last_utime_) : 0.0;
  has_time_ = true;
  last_utime_ = utime;

  bool dropped = false;
  if (valid_ && 1e-6 * static_cast<double>(utime - last_fused_utime_) > options_.max_coast_s) {
    valid_ = false;
    dropped = true;
  }
  if (!valid_) {
    if (box == nullptr) return dropped ? Outcome::kDropped : Outcome::kNoTrack;
    initialise(utime, *box);
    return Outcome::kInitialised;
  }
  predict(dt);
  ++frames_since_fused_;
  if (box == nullptr) return Outcome::kCoasted;

  Eigen::Matrix<double, 4, 8> H = Eigen::Matrix<double, 4, 8>::Zero();
  H.leftCols<4>().setIdentity();
  Eigen::Matrix4d R = Eigen::Matrix4d::Zero();
  R.diagonal() << options_.center_sigma_px * options_.center_sigma_px,
      options_.center_sigma_px * options_.center_sigma_px, options_.size_sigma_px * options_.size_sigma_px,
      options_.size_sigma_px * options_.size_sigma_px;
  const Eigen::Vector4d y = center_form(*box) - H * x_;
  const Eigen::Matrix4d S = H * P_ * H.transpose() + R;
  const Eigen::LDLT<Eigen::Matrix4d> S_ldlt(S);
  last_d2_ = y.dot(S_ldlt.solve(y));
  if (last_d2_ > gate_) {
    if (++consecutive_rejections_ < options_.max_consecutive_rejections) return Outcome::kRejected;
    initialise(utime, *box);
    return Outcome::kReinitialised;
  }
  const Eigen::Matrix<double, 8, 4> K = S_ldlt.solve(H * P_).transpose();
  x_ += K * y;
  // Joseph form: stays symmetric positive definite.
  const Matrix8d I_KH = Matrix8d::Identity() - K * H;
  P_ = I_KH * P_ * I_KH.transpose() + K * R * K.transpose();
  last_fused_utime_ = utime;
  frames_since_fused_ = 0;
  consecutive_rejections_ = 0;
  return Outcome::kFused;
}

Eigen::Vector4d BoxKalmanFilter::box() const {
  const double w = std::max(0.0, x_(2));
  const double h = std::max(0.0, x_(3));
  return {x_(0) - 0.5 * w, x_(1) - 0.5 * h, w, h};
}

Eigen::Matrix4d BoxKalmanFilter::box_covariance() const {
  const Eigen::Matrix4d J = box_jacobian();
  return J * P_.topLeftCorner<4, 4>() * J.transpose();
}

}  // namespace vimot::segmentation

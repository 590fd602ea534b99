#include "common/sim/bspline_se3.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot {
namespace sim {

namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// Evaluation outside [start, end] by less than this (s) is clamped: ticks
// are rounded to whole microseconds.
constexpr double kTimeTolerance = 1e-9;

Eigen::Matrix4d hat_se3(const Vector6d& xi) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.topLeftCorner<3, 3>() = skew(xi.head<3>());
  m.topRightCorner<3, 1>() = xi.tail<3>();
  return m;
}

std::string fmt(double v) {
  std::ostringstream ss;
  ss.precision(12);
  ss << v;
  return ss.str();
}

}  // namespace

Eigen::Matrix4d exp_se3(const Vector6d& xi) {
  const Eigen::Vector3d w = xi.head<3>();
  return make_se3(exp_so3(w), jl_so3(w) * xi.tail<3>());
}

Vector6d log_se3(const Eigen::Matrix4d& T) {
  const Eigen::Vector3d w = log_so3(T.topLeftCorner<3, 3>());
  Vector6d xi;
  xi.head<3>() = w;
  xi.tail<3>() = jl_so3(w).lu().solve(Eigen::Vector3d(T.topRightCorner<3, 1>()));
  return xi;
}

Eigen::Matrix4d inverse_se3(const Eigen::Matrix4d& T) {
  const Eigen::Matrix3d Rt = T.topLeftCorner<3, 3>().transpose();
  return make_se3(Rt, -Rt * T.topRightCorner<3, 1>());
}

Eigen::Matrix4d make_se3(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = p;
  return T;
}

BsplineSE3::BsplineSE3(double t0, double dt, std::vector<Eigen::Matrix4d> control_T_BtoG)
    : t0_(t0), dt_(dt), control_(std::move(control_T_BtoG)) {
  if (!std::isfinite(t0) || !(dt > 0.0) || !std::isfinite(dt)) {
    throw std::invalid_argument("BsplineSE3: need finite t0 and dt > 0, got t0 = " + fmt(t0) + ", dt = " + fmt(dt));
  }
  if (control_.size() < 4) {
    throw std::invalid_argument("BsplineSE3: need at least 4 control poses, got " + std::to_string(control_.size()));
  }
  omega_.reserve(control_.size() - 1);
  for (std::size_t k = 0; k + 1 < control_.size(); ++k) {
    if (!control_[k].allFinite() || !control_[k + 1].allFinite()) {
      throw std::invalid_argument("BsplineSE3: control pose " + std::to_string(k) + " is not finite");
    }
    omega_.push_back(log_se3(inverse_se3(control_[k]) * control_[k + 1]));
  }
}

BsplineSE3 BsplineSE3::fit(const std::vector<TimedPose>& poses, double dt) {
  if (poses.size() < 2) {
    throw std::invalid_argument("BsplineSE3::fit: need at least 2 poses, got " + std::to_string(poses.size()));
  }
  for (std::size_t k = 1; k < poses.size(); ++k) {
    if (!(poses[k].t > poses[k - 1].t)) {
      throw std::invalid_argument("BsplineSE3::fit: times must increase strictly, pose " + std::to_string(k) +
                                  " has t = " + fmt(poses[k].t) + " after " + fmt(poses[k - 1].t));
    }
  }
  const double t_first = poses.front().t;
  const double t_last = poses.back().t;
  std::vector<Eigen::Matrix4d> control;
  std::size_t j = 0;  // poses[j].t <= t < poses[j + 1].t
  for (int k = 0;; ++k) {
    const double t = t_first + dt * static_cast<double>(k);
    if (t > t_last + kTimeTolerance) break;
    while (j + 2 < poses.size() && poses[j + 1].t <= t) ++j;
    const TimedPose& a = poses[j];
    const TimedPose& b = poses[j + 1];
    const double lambda = std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
    const Eigen::Matrix3d R = a.R_BtoG * exp_so3(lambda * log_so3(a.R_BtoG.transpose() * b.R_BtoG));
    const Eigen::Vector3d p = (1.0 - lambda) * a.p_BinG + lambda * b.p_BinG;
    control.push_back(make_se3(R, p));
  }
  if (control.size() < 4) {
    throw std::invalid_argument("BsplineSE3::fit: poses span " + fmt(t_last - t_first) +
                                " s, too short for a spline with dt = " + fmt(dt) + " s (needs 3 dt)");
  }
  return BsplineSE3(t_first, dt, std::move(control));
}

BsplineSE3 BsplineSE3::from_function(const std::function<Eigen::Matrix4d(double)>& T_BtoG_of_t, double t_begin,
                                     double t_end, double dt) {
  if (!(t_end >= t_begin) || !(dt > 0.0)) {
    throw std::invalid_argument("BsplineSE3::from_function: need t_end >= t_begin and dt > 0, got [" + fmt(t_begin) +
                                ", " + fmt(t_end) + "], dt = " + fmt(dt));
  }
  // t_k = t_begin + (k - 1) dt; the spline is valid on [t_1, t_{n-2}].
  const int segments = static_cast<int>(std::ceil((t_end - t_begin) / dt - 1e-9));
  const int n = std::max(segments, 1) + 3;
  std::vector<Eigen::Matrix4d> control;
  control.reserve(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) control.push_back(T_BtoG_of_t(t_begin + dt * static_cast<double>(k - 1)));
  return BsplineSE3(t_begin - dt, dt, std::move(control));
}

bool BsplineSE3::valid(double t) const {
  return t >= start_time() - kTimeTolerance && t <= end_time() + kTimeTolerance;
}

void BsplineSE3::locate(double t, int* i, double* u) const {
  if (!valid(t)) {
    throw std::out_of_range("BsplineSE3: time " + fmt(t) + " s outside the valid range [" + fmt(start_time()) + ", " +
                            fmt(end_time()) + "] s");
  }
  const int n = static_cast<int>(control_.size());
  const double s = (t - t0_) / dt_;
  const int seg = std::clamp(static_cast<int>(std::floor(s)), 1, n - 3);
  *i = seg;
  *u = std::clamp(s - static_cast<double>(seg), 0.0, 1.0);
}

Eigen::Matrix4d BsplineSE3::pose(double t) const {
  int i = 0;
  double u = 0.0;
  locate(t, &i, &u);
  const double u2 = u * u, u3 = u2 * u;
  const double b1 = (5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0;
  const double b2 = (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0;
  const double b3 = u3 / 6.0;
  const std::size_t k = static_cast<std::size_t>(i);
  return control_[k - 1] * exp_se3(b1 * omega_[k - 1]) * exp_se3(b2 * omega_[k]) * exp_se3(b3 * omega_[k + 1]);
}

SplineState BsplineSE3::evaluate(double t) const {
  int i = 0;
  double u = 0.0;
  locate(t, &i, &u);
  const double u2 = u * u, u3 = u2 * u;
  // Basis, first and second derivatives with respect to time.
  const double b[3] = {(5.0 + 3.0 * u - 3.0 * u2 + u3) / 6.0, (1.0 + 3.0 * u + 3.0 * u2 - 2.0 * u3) / 6.0, u3 / 6.0};
  const double inv_dt = 1.0 / dt_;
  const double db[3] = {(3.0 - 6.0 * u + 3.0 * u2) / 6.0 * inv_dt, (3.0 + 6.0 * u - 6.0 * u2) / 6.0 * inv_dt,
                        0.5 * u2 * inv_dt};
  const double inv_dt2 = inv_dt * inv_dt;
  const double ddb[3] = {(u - 1.0) * inv_dt2, (1.0 - 2.0 * u) * inv_dt2, u * inv_dt2};

  const std::size_t k = static_cast<std::size_t>(i);
  Eigen::Matrix4d A[3], dA[3], ddA[3];
  for (int j = 0; j < 3; ++j) {
    const Vector6d& om = omega_[k - 1 + static_cast<std::size_t>(j)];
    const Eigen::Matrix4d H = hat_se3(om);
    A[j] = exp_se3(b[j] * om);
    dA[j] = A[j] * H * db[j];
    ddA[j] = A[j] * (H * H * (db[j] * db[j]) + H * ddb[j]);
  }
  const Eigen::Matrix4d& P0 = control_[k - 1];
  const Eigen::Matrix4d T = P0 * A[0] * A[1] * A[2];
  const Eigen::Matrix4d dT = P0 * (dA[0] * A[1] * A[2] + A[0] * dA[1] * A[2] + A[0] * A[1] * dA[2]);
  const Eigen::Matrix4d ddT =
      P0 * (ddA[0] * A[1] * A[2] + A[0] * ddA[1] * A[2] + A[0] * A[1] * ddA[2] +
            2.0 * (dA[0] * dA[1] * A[2] + dA[0] * A[1] * dA[2] + A[0] * dA[1] * dA[2]));

  SplineState s;
  s.t = t;
  s.R_BtoG = T.topLeftCorner<3, 3>();
  s.p_BinG = T.topRightCorner<3, 1>();
  s.v_BinG = dT.topRightCorner<3, 1>();
  s.a_BinG = ddT.topRightCorner<3, 1>();
  const Eigen::Matrix3d Rt = s.R_BtoG.transpose();
  s.w_BinB = vee(Rt * dT.topLeftCorner<3, 3>());
  s.alpha_BinB = vee(Rt * ddT.topLeftCorner<3, 3>());
  return s;
}

}  // namespace sim
}  // namespace vimot

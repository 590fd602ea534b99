#include "common/math/quat.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace vimot {

namespace {
// Below this angle (rad) the series expansions are used: the closed forms
// divide by θ² or θ³ and lose all precision.
constexpr double kSmallAngle = 1e-7;
}  // namespace

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(),
       a.z(), 0.0, -a.x(),
      -a.y(), a.x(), 0.0;
  return m;
}

Eigen::Vector3d vee(const Eigen::Matrix3d& m) {
  return 0.5 * Eigen::Vector3d(m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
}

Eigen::Matrix3d exp_so3(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  const Eigen::Matrix3d K = skew(theta);
  if (angle < kSmallAngle) return Eigen::Matrix3d::Identity() + K + 0.5 * K * K;
  return Eigen::Matrix3d::Identity() + std::sin(angle) / angle * K +
         (1.0 - std::cos(angle)) / (angle * angle) * K * K;
}

Eigen::Vector3d log_so3(const Eigen::Matrix3d& R) {
  // Eigen's AngleAxis is accurate near 0 and π, where the trace formula fails.
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

Eigen::Matrix3d jl_so3(const Eigen::Vector3d& theta) {
  const double angle = theta.norm();
  const Eigen::Matrix3d K = skew(theta);
  if (angle < kSmallAngle) return Eigen::Matrix3d::Identity() + 0.5 * K + K * K / 6.0;
  const double a2 = angle * angle;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(angle)) / a2 * K +
         (angle - std::sin(angle)) / (a2 * angle) * K * K;
}

Eigen::Matrix3d jr_so3(const Eigen::Vector3d& theta) { return jl_so3(-theta); }

Eigen::Matrix3d quat_to_rot(const Eigen::Vector4d& q) {
  const Eigen::Vector3d qv = q.head<3>();
  const double qw = q(3);
  return (2.0 * qw * qw - 1.0) * Eigen::Matrix3d::Identity() - 2.0 * qw * skew(qv) +
         2.0 * qv * qv.transpose();
}

Eigen::Vector4d rot_to_quat(const Eigen::Matrix3d& R) {
  // The JPL quaternion of R has the components of the Hamilton quaternion of
  // R^T; Eigen's Hamilton conversion picks the numerically safe branch.
  const Eigen::Quaterniond h(Eigen::Matrix3d(R.transpose()));
  return quat_normalize(Eigen::Vector4d(h.x(), h.y(), h.z(), h.w()));
}

Eigen::Vector4d quat_multiply(const Eigen::Vector4d& q, const Eigen::Vector4d& p) {
  const Eigen::Vector3d qv = q.head<3>();
  const Eigen::Vector3d pv = p.head<3>();
  Eigen::Vector4d out;
  out.head<3>() = q(3) * pv + p(3) * qv - qv.cross(pv);
  out(3) = q(3) * p(3) - qv.dot(pv);
  return quat_normalize(out);
}

Eigen::Vector4d quat_inverse(const Eigen::Vector4d& q) {
  return Eigen::Vector4d(-q(0), -q(1), -q(2), q(3));
}

Eigen::Vector4d quat_normalize(const Eigen::Vector4d& q) {
  const double n = q.norm();
  if (!std::isfinite(n) || n < 1e-12) {
    std::ostringstream msg;
    msg << "quat_normalize: not a rotation: [" << q.transpose() << "]";
    throw std::invalid_argument(msg.str());
  }
  return (q(3) < 0.0 ? -q : q) / n;
}

Eigen::Matrix4d omega_matrix(const Eigen::Vector3d& w) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Zero();
  m.topLeftCorner<3, 3>() = -skew(w);
  m.topRightCorner<3, 1>() = w;
  m.bottomLeftCorner<1, 3>() = -w.transpose();
  return m;
}

Eigen::Vector4d small_angle_quat(const Eigen::Vector3d& theta) {
  const double half = 0.5 * theta.norm();
  if (half < kSmallAngle) return quat_normalize(Eigen::Vector4d(0.5 * theta.x(), 0.5 * theta.y(), 0.5 * theta.z(), 1.0));
  const Eigen::Vector3d v = std::sin(half) / theta.norm() * theta;
  return Eigen::Vector4d(v.x(), v.y(), v.z(), std::cos(half));
}

Eigen::Vector4d quat_boxplus(const Eigen::Vector4d& q, const Eigen::Vector3d& dtheta) {
  return quat_multiply(small_angle_quat(dtheta), q);
}

Eigen::Vector4d hamilton_ItoG_to_jpl_GtoI(const Eigen::Vector4d& q_hamilton_ItoG) {
  return quat_normalize(q_hamilton_ItoG);
}

Eigen::Vector4d jpl_GtoI_to_hamilton_ItoG(const Eigen::Vector4d& q_GtoI) {
  return quat_normalize(q_GtoI);
}

double rotation_angle_between(const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb) {
  return log_so3(Ra * Rb.transpose()).norm();
}

}  // namespace vimot

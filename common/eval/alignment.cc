#include "common/eval/alignment.h"

#include <cmath>

#include "common/math/quat.h"

namespace vimot {
namespace eval {

namespace {
Eigen::Matrix3d rot_z(double yaw) {
  Eigen::Matrix3d R;
  R << std::cos(yaw), -std::sin(yaw), 0.0, std::sin(yaw), std::cos(yaw), 0.0, 0.0, 0.0, 1.0;
  return R;
}
}  // namespace

YawAlignment align_position_yaw(const std::vector<PosePair>& pairs) {
  YawAlignment a;
  if (pairs.empty()) return a;
  const double n = static_cast<double>(pairs.size());
  Eigen::Vector3d mu_e = Eigen::Vector3d::Zero(), mu_g = Eigen::Vector3d::Zero();
  for (const PosePair& p : pairs) {
    mu_e += p.p_IinG_est / n;
    mu_g += p.p_IinG_true / n;
  }
  // min Σ|g − Rz e|² over the yaw: maximise Σ gᵀ Rz e = cos ψ Σ(ex gx + ey gy) + sin ψ Σ(ex gy − ey gx).
  double c = 0.0, s = 0.0;
  for (const PosePair& p : pairs) {
    const Eigen::Vector3d e = p.p_IinG_est - mu_e, g = p.p_IinG_true - mu_g;
    c += e.x() * g.x() + e.y() * g.y();
    s += e.x() * g.y() - e.y() * g.x();
  }
  a.yaw = (c == 0.0 && s == 0.0) ? 0.0 : std::atan2(s, c);
  a.t = mu_g - rot_z(a.yaw) * mu_e;
  return a;
}

AlignedErrors aligned_errors(const std::vector<PosePair>& pairs) {
  AlignedErrors r;
  r.alignment = align_position_yaw(pairs);
  r.count = static_cast<int>(pairs.size());
  if (pairs.empty()) return r;
  const Eigen::Matrix3d Rz = rot_z(r.alignment.yaw);
  double sp = 0.0, st = 0.0;
  for (const PosePair& p : pairs) {
    sp += (p.p_IinG_true - (Rz * p.p_IinG_est + r.alignment.t)).squaredNorm();
    // R_ItoG' = Rz R_ItoG  ->  R_GtoI' = R_GtoI Rzᵀ
    const double angle = rotation_angle_between(quat_to_rot(p.q_GtoI_true), quat_to_rot(p.q_GtoI_est) * Rz.transpose());
    st += angle * angle;
  }
  r.ate_position_m = std::sqrt(sp / r.count);
  r.ate_orientation_deg = std::sqrt(st / r.count) * 180.0 / M_PI;
  return r;
}

}  // namespace eval
}  // namespace vimot

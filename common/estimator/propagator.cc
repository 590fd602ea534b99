#include "common/estimator/propagator.h"

#include "common/estimator/vio_extension.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/estimator/state_helper.h"
#include "common/math/quat.h"
#include "common/time/utime.h"

namespace vimot {
namespace estimator {

namespace {

// 4-point Gauss–Legendre on [-1, 1].
constexpr double kGlNodes[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
constexpr double kGlWeights[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};

ImuData lerp(const ImuData& a, const ImuData& b, int64_t t) {
  const double lambda = static_cast<double>(t - a.utime) / static_cast<double>(b.utime - a.utime);
  ImuData out;
  out.utime = t;
  out.w_IinI = (1.0 - lambda) * a.w_IinI + lambda * b.w_IinI;
  out.a_IinI = (1.0 - lambda) * a.a_IinI + lambda * b.a_IinI;
  return out;
}

}  // namespace

const char* to_string(ImuFeedStatus status) {
  switch (status) {
    case ImuFeedStatus::kAccepted: return "accepted";
    case ImuFeedStatus::kAcceptedAfterGap: return "accepted after gap";
    case ImuFeedStatus::kRejectedNonFinite: return "rejected: non-finite";
    case ImuFeedStatus::kRejectedDuplicate: return "rejected: duplicate utime";
    case ImuFeedStatus::kRejectedOutOfOrder: return "rejected: out of order";
  }
  return "unknown";
}

Propagator::Propagator(const PropagatorOptions& options) : options_(options) {
  const ImuNoise& n = options_.noise;
  if (!(n.sigma_w > 0.0) || !(n.sigma_a > 0.0) || !(n.sigma_wb >= 0.0) || !(n.sigma_ab >= 0.0)) {
    std::ostringstream msg;
    msg << "PropagatorOptions: IMU noise densities must be positive, got sigma_w " << n.sigma_w << ", sigma_a "
        << n.sigma_a << ", sigma_wb " << n.sigma_wb << ", sigma_ab " << n.sigma_ab;
    throw std::invalid_argument(msg.str());
  }
  if (!(options_.gravity_magnitude > 0.0) || !(options_.max_gap_s > 0.0) || !(options_.buffer_s > 0.0)) {
    throw std::invalid_argument("PropagatorOptions: gravity_magnitude, max_gap_s and buffer_s must be positive");
  }
}

ImuFeedStatus Propagator::feed_imu(const ImuData& imu) {
  if (!imu.w_IinI.allFinite() || !imu.a_IinI.allFinite()) {
    ++counts_.non_finite;
    return ImuFeedStatus::kRejectedNonFinite;
  }
  if (!buffer_.empty()) {
    const int64_t last = buffer_.back().utime;
    if (imu.utime == last) {
      ++counts_.duplicate;
      return ImuFeedStatus::kRejectedDuplicate;
    }
    if (imu.utime < last) {
      ++counts_.out_of_order;
      return ImuFeedStatus::kRejectedOutOfOrder;
    }
  }
  const bool gap = !buffer_.empty() && utime_to_seconds(imu.utime - buffer_.back().utime) > options_.max_gap_s;
  buffer_.push_back(imu);
  ++counts_.accepted;
  // Bounded memory: keep buffer_s of history (at least two samples).
  const int64_t keep = seconds_to_utime(options_.buffer_s);
  while (buffer_.size() > 2 && buffer_.back().utime - buffer_[1].utime > keep) buffer_.pop_front();
  if (gap) {
    ++counts_.gaps;
    return ImuFeedStatus::kAcceptedAfterGap;
  }
  return ImuFeedStatus::kAccepted;
}

bool Propagator::prepend(const ImuData& imu) {
  if (!imu.w_IinI.allFinite() || !imu.a_IinI.allFinite()) return false;
  if (!buffer_.empty() && imu.utime >= buffer_.front().utime) return false;
  buffer_.push_front(imu);
  return true;
}

void Propagator::clean_older_than(int64_t utime) {
  // Keep the last sample at or before utime for interpolation.
  while (buffer_.size() >= 2 && buffer_[1].utime <= utime) buffer_.pop_front();
}

std::vector<ImuData> Propagator::select_readings(int64_t t0, int64_t t1, PropagationReport* report) const {
  std::vector<ImuData> out;
  if (buffer_.empty() || t1 <= t0) return out;
  // Start: interpolate between the samples around t0 (hold the first if t0 precedes it).
  const auto after0 = std::upper_bound(buffer_.begin(), buffer_.end(), t0,
                                       [](int64_t t, const ImuData& d) { return t < d.utime; });
  ImuData start;
  if (after0 == buffer_.begin()) {
    start = buffer_.front();
  } else if (after0 == buffer_.end()) {
    start = buffer_.back();
  } else {
    start = lerp(*(after0 - 1), *after0, t0);
  }
  start.utime = t0;
  out.push_back(start);
  auto it = after0;
  for (; it != buffer_.end() && it->utime < t1; ++it) out.push_back(*it);
  ImuData end;
  if (it != buffer_.end()) {
    end = (it->utime == t1 || it == buffer_.begin()) ? *it : lerp(*(it - 1), *it, t1);
  } else {
    end = out.back();
    if (report) report->extrapolated = true;
  }
  end.utime = t1;
  out.push_back(end);
  return out;
}

void Propagator::gamma_integrals(const Eigen::Vector3d& w, double dt, Eigen::Matrix3d* G1, Eigen::Matrix3d* G2) {
  const double theta = w.norm();
  const double phi = theta * dt;
  const Eigen::Matrix3d K = skew(w);
  const Eigen::Matrix3d K2 = K * K;
  const double dt2 = dt * dt;
  double c1, c2, c3;  // coefficients of K, K² as in the header
  if (phi < 1e-2) {
    const double p2 = phi * phi;
    const double p4 = p2 * p2;
    c1 = dt2 * (0.5 - p2 / 24.0 + p4 / 720.0);
    c2 = dt2 * dt * (1.0 / 6.0 - p2 / 120.0 + p4 / 5040.0);
    c3 = dt2 * dt2 * (1.0 / 24.0 - p2 / 720.0 + p4 / 40320.0);
  } else {
    const double t2 = theta * theta;
    c1 = (1.0 - std::cos(phi)) / t2;
    c2 = (phi - std::sin(phi)) / (t2 * theta);
    c3 = (0.5 * phi * phi - 1.0 + std::cos(phi)) / (t2 * t2);
  }
  *G1 = dt * Eigen::Matrix3d::Identity() + c1 * K + c2 * K2;
  *G2 = 0.5 * dt2 * Eigen::Matrix3d::Identity() + c2 * K + c3 * K2;
}

void Propagator::predict_step(const ImuValue& x, const ImuValue& x_lin, const Eigen::Vector3d& w_m,
                              const Eigen::Vector3d& a_m, double dt, const Eigen::Vector3d& gravity,
                              const ImuNoise& noise, ImuValue* x_new, Matrix15d* Phi, Matrix15d* Qd) {
  const Eigen::Vector3d w = w_m - x.bg;
  const Eigen::Vector3d a = a_m - x.ba;
  Eigen::Matrix3d G1, G2;
  gamma_integrals(w, dt, &G1, &G2);
  const Eigen::Matrix3d R_k = quat_to_rot(x.q_GtoI);

  ImuValue xn = x;
  xn.q_GtoI = quat_multiply(rot_to_quat(exp_so3(-w * dt)), x.q_GtoI);
  xn.v_IinG = x.v_IinG + R_k.transpose() * (G1 * a) - gravity * dt;
  xn.p_IinG = x.p_IinG + x.v_IinG * dt + R_k.transpose() * (G2 * a) - 0.5 * gravity * dt * dt;
  *x_new = xn;
  if (Phi == nullptr) return;

  // D1, D2 by Gauss–Legendre quadrature on [0, dt].
  Eigen::Matrix3d D1 = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d D2 = Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d a_x = skew(a);
  for (int i = 0; i < 4; ++i) {
    const double tau = 0.5 * dt * (kGlNodes[i] + 1.0);
    const double wgt = 0.5 * dt * kGlWeights[i];
    const Eigen::Vector3d wt = w * tau;
    const Eigen::Matrix3d f = exp_so3(wt) * a_x * jr_so3(wt) * tau;
    D1 -= wgt * f;
    D2 -= wgt * (dt - tau) * f;
  }

  const Eigen::Matrix3d R_new = quat_to_rot(xn.q_GtoI);
  const Eigen::Matrix3d R_lin_T = quat_to_rot(x_lin.q_GtoI).transpose();
  Matrix15d F = Matrix15d::Identity();
  F.block<3, 3>(0, 0) = R_new * R_lin_T;
  F.block<3, 3>(0, 9) = -jr_so3(w * dt) * dt;
  F.block<3, 3>(3, 0) =
      -skew(xn.p_IinG - x_lin.p_IinG - x_lin.v_IinG * dt + 0.5 * gravity * dt * dt) * R_lin_T;
  F.block<3, 3>(3, 6) = dt * Eigen::Matrix3d::Identity();
  F.block<3, 3>(3, 9) = -R_lin_T * D2;
  F.block<3, 3>(3, 12) = -R_lin_T * G2;
  F.block<3, 3>(6, 0) = -skew(xn.v_IinG - x_lin.v_IinG + gravity * dt) * R_lin_T;
  F.block<3, 3>(6, 9) = -R_lin_T * D1;
  F.block<3, 3>(6, 12) = -R_lin_T * G1;
  *Phi = F;

  if (Qd == nullptr) return;
  Eigen::Matrix<double, 9, 3> Gg, Ga;
  Gg = F.block<9, 3>(0, 9);
  Ga = F.block<9, 3>(0, 12);
  Matrix15d Q = Matrix15d::Zero();
  Q.topLeftCorner<9, 9>() = Gg * Gg.transpose() * (noise.sigma_w * noise.sigma_w / dt) +
                            Ga * Ga.transpose() * (noise.sigma_a * noise.sigma_a / dt);
  Q.block<3, 3>(9, 9) = noise.sigma_wb * noise.sigma_wb * dt * Eigen::Matrix3d::Identity();
  Q.block<3, 3>(12, 12) = noise.sigma_ab * noise.sigma_ab * dt * Eigen::Matrix3d::Identity();
  *Qd = Q;
}

bool Propagator::predict_interval(const ImuValue& x0, const ImuValue& x0_lin, int64_t t0, int64_t t1, ImuValue* x1,
                                  Matrix15d* Phi, Matrix15d* Q, PropagationReport* report) const {
  PropagationReport local_report;
  if (report == nullptr) report = &local_report;
  const std::vector<ImuData> readings = select_readings(t0, t1, report);
  if (readings.size() < 2) {
    report->message = "no IMU samples to propagate with";
    return false;
  }
  ImuValue x = x0;
  ImuValue x_lin = x0_lin;
  if (Phi) Phi->setIdentity();
  if (Q) Q->setZero();
  const Eigen::Vector3d g = gravity();
  for (size_t i = 0; i + 1 < readings.size(); ++i) {
    const ImuData& r0 = readings[i];
    const ImuData& r1 = readings[i + 1];
    if (r1.utime <= r0.utime) continue;
    const double dt = utime_to_seconds(r1.utime - r0.utime);
    report->max_step_s = std::max(report->max_step_s, dt);
    if (dt > options_.max_gap_s) report->gap = true;
    // A gap is crossed in sub-steps of interpolated readings with the gap
    // noise added (ImuGapNoise); a regular step is one step.
    const bool bridge = dt > options_.max_gap_s && options_.gap_noise.enabled();
    const int n = bridge ? static_cast<int>(std::ceil(dt / options_.max_gap_s)) : 1;
    ImuNoise noise = options_.noise;
    if (bridge) {
      noise.sigma_w = std::hypot(noise.sigma_w, options_.gap_noise.sigma_w);
      noise.sigma_a = std::hypot(noise.sigma_a, options_.gap_noise.sigma_a);
    }
    for (int k = 0; k < n; ++k) {
      const double s0 = static_cast<double>(k) / n, s1 = static_cast<double>(k + 1) / n, s = 0.5 * (s0 + s1);
      const Eigen::Vector3d w_m = (1.0 - s) * r0.w_IinI + s * r1.w_IinI;
      const Eigen::Vector3d a_m = (1.0 - s) * r0.a_IinI + s * r1.a_IinI;
      const double h = dt / n;
      ImuValue xn;
      if (Phi || Q) {
        Matrix15d F, Qd;
        predict_step(x, x_lin, w_m, a_m, h, g, noise, &xn, &F, &Qd);
        if (Phi) *Phi = F * (*Phi);
        if (Q) *Q = F * (*Q) * F.transpose() + Qd;
      } else {
        predict_step(x, x_lin, w_m, a_m, h, g, noise, &xn, nullptr, nullptr);
      }
      x = xn;
      x_lin = xn;
      ++report->steps;
    }
  }
  *x1 = x;
  if (report->extrapolated) report->message = "no IMU sample at or after the target time: last sample held";
  if (report->gap) {
    report->message += std::string(report->message.empty() ? "" : "; ") + "IMU gap of " +
                       std::to_string(report->max_step_s) + " s";
  }
  return true;
}

PropagationReport Propagator::propagate(State& state, int64_t utime) { return propagate(state, utime, nullptr); }

PropagationReport Propagator::propagate(State& state, int64_t utime, VioExtension* extension) {
  PropagationReport report;
  if (utime <= state.utime()) {
    report.message = "target time " + std::to_string(utime) + " is not after the state time " +
                     std::to_string(state.utime());
    return report;
  }
  const auto& imu = state.imu();
  const ImuValue x0 = imu->get();
  const ImuValue x0_lin = state.options().use_fej ? imu->get_fej() : x0;
  ImuValue x1;
  Matrix15d Phi, Q;
  if (!predict_interval(x0, x0_lin, state.utime(), utime, &x1, &Phi, &Q, &report)) return report;
  std::vector<TypePtr> order;
  Eigen::MatrixXd Phi_joint, Q_joint;
  const bool joint = extension != nullptr && extension->propagate_jointly(state, x0, x1, Phi, Q, state.utime(), utime,
                                                                          &order, &Phi_joint, &Q_joint);
  if (joint) {
    StateHelper::propagate(state, order, Phi_joint, Q_joint);
  } else {
    StateHelper::propagate(state, {imu}, Phi, Q);
  }
  const Eigen::VectorXd v = x1.to_vector();
  imu->set_value(v);
  imu->set_fej(v);
  state.set_utime(utime);
  if (joint) extension->commit_propagation(state);
  report.ok = true;
  return report;
}

PropagationReport Propagator::propagate_and_clone(State& state, int64_t utime) {
  PropagationReport report = propagate(state, utime);
  if (report.ok) StateHelper::augment_clone(state, utime);
  return report;
}

bool Propagator::predict_imu(const State& state, int64_t utime, ImuValue* out) const {
  if (utime <= state.utime()) {
    *out = state.imu()->get();
    return true;
  }
  PropagationReport report;
  return predict_interval(state.imu()->get(), state.imu()->get(), state.utime(), utime, out, nullptr, nullptr, &report);
}

}  // namespace estimator
}  // namespace vimot

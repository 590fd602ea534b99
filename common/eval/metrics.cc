#include "common/eval/metrics.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot {
namespace eval {

Eigen::Vector3d orientation_error(const Eigen::Vector4d& q_GtoI_true, const Eigen::Vector4d& q_GtoI_est) {
  // R_true = Exp(−δθ) R̂  ⇒  δθ = −log(R_true R̂ᵀ).
  return -log_so3(quat_to_rot(q_GtoI_true) * quat_to_rot(q_GtoI_est).transpose());
}

double nees3(const Eigen::Vector3d& e, const Eigen::Matrix3d& P) {
  const Eigen::LLT<Eigen::Matrix3d> llt(0.5 * (P + P.transpose()));
  if (!P.allFinite() || llt.info() != Eigen::Success || (P - P.transpose()).cwiseAbs().maxCoeff() >
                                                             1e-9 * std::max(1.0, P.cwiseAbs().maxCoeff())) {
    std::ostringstream s;
    s << "nees3: covariance block is not symmetric positive definite:\n" << P;
    throw std::invalid_argument(s.str());
  }
  return e.dot(llt.solve(e));
}

ErrorSample compute_error(int64_t utime, const Eigen::Vector4d& q_GtoI_true, const Eigen::Vector3d& p_IinG_true,
                          const Eigen::Vector4d& q_GtoI_est, const Eigen::Vector3d& p_IinG_est,
                          const Eigen::Matrix3d& P_theta, const Eigen::Matrix3d& P_p) {
  ErrorSample s;
  s.utime = utime;
  s.err_p = p_IinG_true - p_IinG_est;
  s.err_theta = orientation_error(q_GtoI_true, q_GtoI_est);
  s.sig3_p = 3.0 * P_p.diagonal().cwiseMax(0.0).cwiseSqrt();
  s.sig3_theta = 3.0 * P_theta.diagonal().cwiseMax(0.0).cwiseSqrt();
  s.nees_p = nees3(s.err_p, P_p);
  s.nees_theta = nees3(s.err_theta, P_theta);
  return s;
}

ErrorSample error_of(const NavState& est, const GroundTruth& truth) {
  return compute_error(est.utime, truth.q_GtoI, truth.p_IinG, est.q_GtoI, est.p_IinG,
                       est.covariance.block<3, 3>(0, 0), est.covariance.block<3, 3>(3, 3));
}

TargetInImu true_target_in_imu(const GroundTruth& truth) {
  const Eigen::Matrix3d R_GtoI = quat_to_rot(truth.q_GtoI);
  return TargetInImu{rot_to_quat(quat_to_rot(truth.q_GtoT) * R_GtoI.transpose()),
                     R_GtoI * (truth.p_TinG - truth.p_IinG)};
}

void TrajectoryErrors::add(const ErrorSample& s) {
  sum_sq_p_ += s.err_p.squaredNorm();
  sum_sq_theta_ += s.err_theta.squaredNorm();
  sum_nees_p_ += s.nees_p;
  sum_nees_theta_ += s.nees_theta;
  // tr P from the 3σ bounds: Σ (3σ_i / 3)².
  sum_trace_p_ += (s.sig3_p / 3.0).squaredNorm();
  sum_trace_theta_ += (s.sig3_theta / 3.0).squaredNorm();
  ++count_;
}

ErrorSummary TrajectoryErrors::summary() const {
  ErrorSummary r;
  r.count = count_;
  if (count_ == 0) return r;
  const double n = static_cast<double>(count_);
  r.rmse_position_m = std::sqrt(sum_sq_p_ / n);
  r.rmse_orientation_deg = std::sqrt(sum_sq_theta_ / n) * 180.0 / M_PI;
  r.nees_position = sum_nees_p_ / n;
  r.nees_orientation = sum_nees_theta_ / n;
  r.predicted_rmse_position_m = std::sqrt(sum_trace_p_ / n);
  r.predicted_rmse_orientation_deg = std::sqrt(sum_trace_theta_ / n) * 180.0 / M_PI;
  return r;
}

MeanStd mean_std(const std::vector<double>& v) {
  MeanStd r;
  if (v.empty()) return r;
  const double n = static_cast<double>(v.size());
  r.mean = std::accumulate(v.begin(), v.end(), 0.0) / n;
  if (v.size() < 2) return r;
  double ss = 0.0;
  for (double x : v) ss += (x - r.mean) * (x - r.mean);
  r.std = std::sqrt(ss / (n - 1.0));
  return r;
}

MonteCarloSummary aggregate(const std::vector<ErrorSummary>& runs) {
  MonteCarloSummary m;
  m.runs = static_cast<int>(runs.size());
  std::vector<double> rp, rt, np, nt, pp, pt;
  for (const ErrorSummary& r : runs) {
    rp.push_back(r.rmse_position_m);
    rt.push_back(r.rmse_orientation_deg);
    np.push_back(r.nees_position);
    nt.push_back(r.nees_orientation);
    pp.push_back(r.predicted_rmse_position_m);
    pt.push_back(r.predicted_rmse_orientation_deg);
    m.samples += r.count;
  }
  m.rmse_position_m = mean_std(rp);
  m.rmse_orientation_deg = mean_std(rt);
  m.nees_position = mean_std(np);
  m.nees_orientation = mean_std(nt);
  m.predicted_rmse_position_m = mean_std(pp);
  m.predicted_rmse_orientation_deg = mean_std(pt);
  return m;
}

TimingStats timing_stats(std::vector<double> ms) {
  TimingStats t;
  t.count = static_cast<int64_t>(ms.size());
  if (ms.empty()) return t;
  std::sort(ms.begin(), ms.end());
  const std::size_t n = ms.size();
  t.mean_ms = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(n);
  t.median_ms = n % 2 == 1 ? ms[n / 2] : 0.5 * (ms[n / 2 - 1] + ms[n / 2]);
  const std::size_t rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(n)));
  t.p95_ms = ms[std::max<std::size_t>(rank, 1) - 1];
  t.max_ms = ms.back();
  return t;
}

}  // namespace eval
}  // namespace vimot

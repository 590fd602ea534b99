#include "common/eval/truth_matcher.h"

#include <cmath>
#include <limits>
#include <stdexcept>


namespace vimot {
namespace eval {

void TruthMatcher::add_state(const NavState& state) {
  ++counts_.states;
  if (!state.updated) return;
  ++counts_.updated_states;
  if (!states_.emplace(state.utime, state).second) ++counts_.duplicate_states;
}

void TruthMatcher::add_truth(const GroundTruth& truth) {
  ++counts_.truths;
  if (!truths_.emplace(truth.utime, truth).second) ++counts_.duplicate_truths;
}

void TruthMatcher::add_target(const TargetStateEstimate& target) {
  ++target_counts_.states;
  if (!targets_.emplace(target.utime, target).second) ++target_counts_.duplicate_states;
}

std::vector<ErrorSample> TruthMatcher::match(MatchCounts* counts) const {
  MatchCounts c = counts_;
  std::vector<ErrorSample> out;
  out.reserve(states_.size());
  for (const auto& [utime, state] : states_) {
    const auto it = truths_.find(utime);
    if (it == truths_.end()) {
      ++c.unmatched;
      continue;
    }
    ++c.matched;
    try {
      out.push_back(error_of(state, it->second));
    } catch (const std::invalid_argument&) {
      ++c.bad_covariance;
    }
  }
  if (counts != nullptr) *counts = c;
  return out;
}

namespace {

// Error without covariance: NEES and 3σ NaN (not available).
ErrorSample error_without_covariance(int64_t utime, const Eigen::Vector4d& q_true, const Eigen::Vector3d& p_true,
                                     const Eigen::Vector4d& q_est, const Eigen::Vector3d& p_est) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ErrorSample s;
  s.utime = utime;
  s.err_p = p_true - p_est;
  s.err_theta = orientation_error(q_true, q_est);
  s.sig3_p.setConstant(nan);
  s.sig3_theta.setConstant(nan);
  s.nees_p = nan;
  s.nees_theta = nan;
  return s;
}

}  // namespace

TargetMatch TruthMatcher::match_targets(TargetMatchCounts* counts, bool own_frame, int64_t restart_gap_us) const {
  TargetMatchCounts c = target_counts_;
  TargetMatch out;
  bool take_frame = own_frame;
  int64_t previous_utime = -1;
  int previous_start = -1;
  for (const auto& [utime, est] : targets_) {
    // A new target frame: the filter started the target again, or (a process
    // restart without checkpoint) its states stopped for longer than the gap.
    const bool restarted = previous_utime >= 0 && ((restart_gap_us > 0 && utime - previous_utime > restart_gap_us) ||
                                                   est.start_count != previous_start);
    if (own_frame && restarted) {
      take_frame = true;
      ++out.frame_restarts;
    }
    previous_utime = utime;
    previous_start = est.start_count;
    const auto it = truths_.find(utime);
    if (it == truths_.end() || !it->second.has_target) {
      ++c.unmatched;
      continue;
    }
    if (take_frame) {
      out.target_frame = target_frame_transform(it->second, est.q_ItoT, est.p_TinI);
      take_frame = false;
    }
    ++c.matched;
    const GroundTruth t = in_target_frame(it->second, out.target_frame);
    const TargetInImu truth_in_imu = true_target_in_imu(t);
    const Eigen::Vector4d& q_ItoT_true = truth_in_imu.q_ItoT;
    const Eigen::Vector3d& p_TinI_true = truth_in_imu.p_TinI;
    const Eigen::Matrix3d P_theta = est.covariance.block<3, 3>(0, 0);
    const Eigen::Matrix3d P_p = est.covariance.block<3, 3>(3, 3);
    try {
      if (est.representation == TargetFrame::kLocal) {
        out.target_in_imu.push_back(compute_error(utime, q_ItoT_true, p_TinI_true, est.q_ItoT, est.p_TinI, P_theta, P_p));
        out.target_in_world.push_back(error_without_covariance(utime, t.q_GtoT, t.p_TinG, est.q_GtoT, est.p_TinG));
      } else {
        out.target_in_world.push_back(compute_error(utime, t.q_GtoT, t.p_TinG, est.q_GtoT, est.p_TinG, P_theta, P_p));
        out.target_in_imu.push_back(error_without_covariance(utime, q_ItoT_true, p_TinI_true, est.q_ItoT, est.p_TinI));
      }
    } catch (const std::invalid_argument&) {
      ++c.bad_covariance;
    }
  }
  if (counts != nullptr) *counts = c;
  return out;
}

}  // namespace eval
}  // namespace vimot

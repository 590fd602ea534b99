#include "common/eval/truth_matcher.h"

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
  if (!truths_.emplace(truth.utime, Pose{truth.q_GtoI, truth.p_IinG}).second) ++counts_.duplicate_truths;
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
    GroundTruth truth;
    truth.utime = utime;
    truth.q_GtoI = it->second.q_GtoI;
    truth.p_IinG = it->second.p_IinG;
    try {
      out.push_back(error_of(state, truth));
    } catch (const std::invalid_argument&) {
      ++c.bad_covariance;
    }
  }
  if (counts != nullptr) *counts = c;
  return out;
}

}  // namespace eval
}  // namespace vimot

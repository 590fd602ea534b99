#pragma once
// vimot-log-eval's core: reads an LCM log (lcm-logger, vimot-sim --log),
// decodes the estimator's nav_state_t messages and the simulator's
// ground_truth_t messages, and evaluates the updated states against the
// truth at the same utime with vimot_eval's metrics (TruthMatcher), so a
// recorded LCM run and an offline run are measured identically. A message
// that does not decode, or carries non-finite numbers, is counted and
// skipped, never fatal.

#include <cstdint>
#include <string>
#include <vector>

#include "common/eval/metrics.h"
#include "common/eval/truth_matcher.h"

namespace vimot {
namespace eval {

struct LogEvalOptions {
  std::string state_channel{"VINS_STATE"};
  std::string truth_channel{"GROUND_TRUTH"};
};

struct LogEvalResult {
  ErrorSummary summary;
  std::vector<ErrorSample> samples;  // utime order
  MatchCounts counts;
  int64_t events{0};                 // every event in the log
  int64_t malformed_states{0};       // on state_channel, not a valid nav_state_t
  int64_t malformed_truths{0};       // on truth_channel, not a valid ground_truth_t
  std::string first_malformed;       // what was wrong with the first one
};

/// Throws std::runtime_error if the log cannot be opened.
LogEvalResult evaluate_log(const std::string& path, const LogEvalOptions& options = {});

}  // namespace eval
}  // namespace vimot

#pragma once
// Console progress of a Monte Carlo (run_parallel / run_monte_carlo) for the
// evaluator tools: a redrawn bar on a terminal, a line per finished run
// otherwise (logs stay readable). No LCM here.

#include <string>

#include "common/eval/sim_runner.h"

namespace vimot {
namespace eval {

/// "1m05s" / "1h02m03s".
std::string hms(double seconds);

/// Progress on stderr.
class ProgressBar {
 public:
  explicit ProgressBar(bool enabled);
  void update(const MonteCarloProgress& p);

 private:
  bool enabled_;
  bool tty_;
  int last_done_{0};
};

}  // namespace eval
}  // namespace vimot

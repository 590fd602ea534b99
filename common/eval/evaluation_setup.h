#pragma once
// What an offline evaluator runs: a simulator scenario and the estimator of
// a vins config (common/estimator/vins_config.h), and how the estimator's
// model differs from the simulator that produces its data. No LCM here.

#include <optional>
#include <string>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/sim/sim_config.h"

namespace vimot {
namespace eval {

/// The estimator's model against the simulator that produces its data:
/// IMU noise densities and random walks, gravity, pixel noise, the number of
/// cameras used and their calibrations. Returns one line per difference
/// ("pixel noise: estimator 1.5 px, simulator 1 px"); empty when they agree.
std::vector<std::string> model_mismatches(const estimator::VioOptions& options, const sim::SimConfig& sim);

/// VioOptions copied from the simulator (the way tests/estimator started):
/// `base` with the simulator's cameras, pixel noise, IMU noise and gravity.
estimator::VioOptions options_matching_sim(estimator::VioOptions base, const sim::SimConfig& sim);

/// What an offline evaluator runs: the scenario of `sim_yaml` (its duration
/// replaced by `duration_s` if given; it must then be > 0, else
/// std::invalid_argument) and the estimator of `vins_yaml`, with every
/// difference between the estimator's model and the simulator (the tools
/// warn about them).
struct EvaluationSetup {
  sim::SimConfig sim;
  estimator::VioOptions vio;
  std::vector<std::string> model_mismatches;
};
EvaluationSetup load_evaluation_setup(const std::string& sim_yaml, const std::string& vins_yaml,
                                      std::optional<double> duration_s);

}  // namespace eval
}  // namespace vimot

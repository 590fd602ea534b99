#pragma once
// The estimator configuration of the `vins` process, read from the same
// file (config/vins.yaml) by that process and by the offline evaluators, so
// both configure the estimator identically.
//
// config/vins.yaml layout:
//   estimator:        every key of VioOptions::from_config (docs/estimator.md)
//   calibration_file: cameras + IMU noise (ASL layout), relative to the file
//   channels:         imu, features, ground_truth, state (the process's)
//   init:             mode (ground_truth | static), perturb_seed
// No LCM here.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/sim/sim_config.h"

namespace vimot {

class Config;

namespace eval {

/// How the `vins` process starts (top-level `init:` of config/vins.yaml).
struct VinsStartOptions {
  /// ground_truth: from the first GROUND_TRUTH message, via initial_estimate()
  /// (common/eval/initial_estimate.h); static: the estimator's IMU-at-rest
  /// initialisation.
  estimator::InitMode mode{estimator::InitMode::kGroundTruth};
  /// Seed of the initial perturbation x̂0 = x0 ⊞ N(0, P0); 0 = start exactly
  /// at the truth.
  uint64_t perturb_seed{0};
};

/// Estimator options from a vins config file: the `estimator:` section and
/// the cameras and IMU noise of `calibration_file` (resolved relative to the
/// config file's directory; without that key, from the file itself). The
/// top-level `init.mode` sets VioOptions::init_mode. Throws ConfigError
/// naming the file and the key.
estimator::VioOptions load_vio_options(const std::string& vins_yaml);
/// The same from a loaded Config (its source() locates calibration_file).
estimator::VioOptions vio_options_from_config(const Config& vins_cfg);

/// The top-level `init:` section (absent keys keep the defaults above).
VinsStartOptions load_start_options(const std::string& vins_yaml);
VinsStartOptions start_options_from_config(const Config& vins_cfg);

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

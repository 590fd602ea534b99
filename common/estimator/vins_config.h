#pragma once
// The estimator configuration of the `vins` process, read from the same
// file (config/vins.yaml) by the estimator processes and by the offline
// evaluators, so all configure the estimator identically.
//
// config/vins.yaml layout:
//   estimator:        every key of VioOptions::from_config (docs/estimator.md)
//   calibration_file: cameras + IMU noise (ASL layout), relative to the file
//   channels:         imu, features, ground_truth, state (the process's)
//   init:             mode (ground_truth | static), perturb_seed
//   output:           imu_rate (the process's)
// An unknown key anywhere is a ConfigError. No LCM here.

#include <cstdint>
#include <string>
#include <vector>

#include "common/estimator/vio_estimator.h"

namespace vimot {

class Config;

namespace estimator {

/// How the `vins` process starts (top-level `init:` of config/vins.yaml).
struct VinsStartOptions {
  /// ground_truth: from the first GROUND_TRUTH message, via initial_estimate()
  /// (common/estimator/initial_estimate.h); static: the estimator's IMU-at-rest
  /// initialisation.
  InitMode mode{InitMode::kGroundTruth};
  /// Seed of the initial perturbation x̂0 = x0 ⊞ N(0, P0); 0 = start exactly
  /// at the truth.
  uint64_t perturb_seed{0};
};

/// The top-level keys of a vins config file (the layout above).
const std::vector<std::string>& vins_config_keys();

/// Estimator options from a vins config file: the `estimator:` section and
/// the cameras and IMU noise of `calibration_file` (resolved relative to the
/// config file's directory; without that key, from the file itself). The
/// top-level `init.mode` sets VioOptions::init_mode. Throws ConfigError
/// naming the file and the key, also for a top-level key not of a vins config.
VioOptions load_vio_options(const std::string& vins_yaml);
/// The same from a loaded Config (its source() locates calibration_file);
/// its top-level keys are the caller's to check (a file may embed a vins
/// config among its own keys).
VioOptions vio_options_from_config(const Config& vins_cfg);

/// The top-level `init:` section (absent keys keep the defaults above).
VinsStartOptions load_start_options(const std::string& vins_yaml);
VinsStartOptions start_options_from_config(const Config& vins_cfg);

}  // namespace estimator
}  // namespace vimot

#pragma once
// The `target:` section of config/target_filter.yaml, read in this one place
// by the target_filter process and by vimot-target-eval. No LCM here.
//
//   target:
//     mode: skf | ekf | adaptive | off | none   (none: no filter attached, the process
//                                     runs pure VIO; the evaluator refuses it)
//     representation: local | global
//     sigma_t, planar, chi2_multiplier, min_clone_times, observability_constraint,
//     init: {mode: features | ground_truth, frames, min_points,
//            max_point_distance, sigma_w}   (docs/target_model.md),
//     init_sigmas: {theta, p, v, w},
//     points: {max, init_clone_times, max_lost_frames},
//     adaptive: {window, sigma_min, sigma_max, nis_max, max_step}   (mode adaptive),
//     prediction_horizon_s   (the process's TARGET_PREDICTION horizon)
// Every key optional (TargetFilterOptions' defaults); an unknown key or a
// bad value is a ConfigError naming the file and the full key.

#include <string>

#include "common/config/config.h"
#include "common/target/target_filter.h"

namespace vimot {
namespace target {

struct TargetSection {
  TargetFilterOptions filter;
  bool enabled{true};                // false for mode: none
  double prediction_horizon_s{0.5};  // s, >= 0
};

/// Reads `target:` of `config` (absent: the defaults).
TargetSection target_section_from_config(const Config& config);

/// "skf" | "ekf" | "off"; throws std::invalid_argument otherwise.
TargetUpdateMode parse_target_mode(const std::string& s);
/// "local" | "global"; throws std::invalid_argument otherwise.
TargetRepresentation parse_target_representation(const std::string& s);
/// "features" | "ground_truth"; throws std::invalid_argument otherwise.
TargetInitMode parse_init_mode(const std::string& s);

}  // namespace target
}  // namespace vimot

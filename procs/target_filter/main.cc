// target_filter: the joint robot + moving-target filter (Schmidt-EKF paper)
// as an LCM process. Subscribes IMU, FEATURES (static + target
// observations) and GROUND_TRUTH (the robot's start in simulation; the
// target's only with target.init.mode ground_truth); publishes
// per processed frame NAV_STATE (nav_state_t, updated = true),
// TARGET_STATE (target_state_t) and TARGET_PREDICTION (target_prediction_t).
// All logic is in TargetFilterNode / the target library; this file moves bytes.

#include <stdexcept>

#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "common/process/node_runner.h"
#include "common/target/target_filter_config.h"
#include "procs/target_filter/target_filter_node.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("target_filter",
                         "Joint VIO + moving-target filter: IMU + FEATURES in,\n"
                         "NAV_STATE, TARGET_STATE and TARGET_PREDICTION out.\n"
                         "Configured by config/target_filter.yaml (target filter options, channels;\n"
                         "estimator, calibration and initialisation from its vins_config).",
                         /*config_required=*/true);
  process.args().add_option("perturb-seed", "N",
                            "start from ground truth perturbed with this seed (overrides init.perturb_seed)");
  process.args().add_option("mode", "MODE", "ekf, skf, adaptive or off (overrides target.mode)");
  process.args().add_option("checkpoint", "PATH",
                            "robot and target filter state written per update; a restart goes on from it if recent (input.bridge_max_gap_s)");
  vimot::add_catch_up_option(process.args());
  process.args().add_option("max-wait", "SECONDS",
                            "process a queued camera frame after this much wall time without IMU", "0.5");
  if (!process.init(argc, argv)) return 0;

  vimot::TargetFilterNodeOptions options = vimot::node_options_from_config(process.config());
  if (process.args().given("checkpoint")) options.checkpoint_path = process.args().get("checkpoint");
  vimot::set_catch_up(process, &options, /*use_ground_truth=*/true);
  if (process.args().given("mode")) {
    if (!options.target_enabled) throw std::invalid_argument("--mode: target.mode is none (VIO only) in the config");
    options.target.mode = vimot::target::parse_target_mode(process.args().get("mode"));
  }
  if (process.args().given("perturb-seed")) {
    options.perturb_seed = static_cast<uint64_t>(process.args().get_int("perturb-seed"));
  }
  const double max_wait = process.args().get_double("max-wait");

  const std::string nav_channel = process.channel("nav_state", "NAV_STATE");
  const std::string target_channel = process.channel("target_state", "TARGET_STATE");
  const std::string prediction_channel = process.channel("target_prediction", "TARGET_PREDICTION");
  vimot::TargetFilterNode::Callbacks callbacks;
  callbacks.on_nav_state = [&](const vimot::NavState& s) { process.publish(nav_channel, vimot::to_lcm(s)); };
  callbacks.on_target_state = [&](const vimot::TargetStateEstimate& s) {
    process.publish(target_channel, vimot::to_lcm(s));
  };
  callbacks.on_target_prediction = [&](const vimot::TargetPosePrediction& p) {
    process.publish(prediction_channel, vimot::to_lcm(p));
  };
  callbacks.on_event = vimot::report_events_to(process);
  vimot::TargetFilterNode node(options, callbacks);
  if (!options.target_enabled) vimot::log_info("target.mode none: VIO only, no target outputs");
  // Ground truth is always subscribed: the robot's start (simulation), and the target's in init.mode ground_truth.
  const int status = vimot::run_estimator_node(process, node, /*use_ground_truth=*/true, max_wait);
  vimot::log_info("target ", node.target_initialized() ? "initialised" : "not initialised");
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

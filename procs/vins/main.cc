// vins: the MSCKF visual-inertial estimator as an LCM process.
// Subscribes IMU, FEATURES (and GROUND_TRUTH when starting from truth in
// simulation), publishes VINS_STATE: IMU-rate propagated states
// (updated = false) and camera-rate updated states (updated = true).
// All logic is in VinsNode / the estimator library; this file moves bytes.

#include "common/process/lcm_conversions.h"
#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/vins/vins_node.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("vins",
                         "MSCKF visual-inertial odometry: IMU + FEATURES in, VINS_STATE out.\n"
                         "Configured by config/vins.yaml (estimator options, calibration file,\n"
                         "channels, initialisation).",
                         /*config_required=*/true);
  process.args().add_option("perturb-seed", "N",
                            "start from ground truth perturbed with this seed (overrides init.perturb_seed)");
  process.args().add_option("checkpoint", "PATH",
                            "estimator state file written per update; a restart goes on from it if recent (input.bridge_max_gap_s)");
  vimot::add_catch_up_option(process.args());
  process.args().add_option("max-wait", "SECONDS",
                            "process a queued camera frame after this much wall time without IMU", "0.5");
  if (!process.init(argc, argv)) return 0;

  vimot::VinsNodeOptions options = vimot::vins_node_options_from_config(process.config());
  if (process.args().given("checkpoint")) options.checkpoint_path = process.args().get("checkpoint");
  vimot::set_catch_up(process, &options, options.init_from_ground_truth);
  if (process.args().given("perturb-seed")) {
    options.perturb_seed = static_cast<uint64_t>(process.args().get_int("perturb-seed"));
  }
  const double max_wait = process.args().get_double("max-wait");

  const std::string state_channel = process.channel("state", "VINS_STATE");
  vimot::VinsNode node(
      options, [&](const vimot::NavState& s) { process.publish(state_channel, vimot::to_lcm(s)); },
      vimot::report_events_to(process));
  return vimot::run_estimator_node(process, node, options.init_from_ground_truth, max_wait);
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

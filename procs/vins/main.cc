// vins: the MSCKF visual-inertial estimator as an LCM process.
// Subscribes IMU, FEATURES (and GROUND_TRUTH when starting from truth in
// simulation), publishes VINS_STATE: IMU-rate propagated states
// (updated = false) and camera-rate updated states (updated = true).
// All logic is in VinsNode / the estimator library; this file moves bytes.
#include <chrono>

#include "common/eval/vins_config.h"
#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "procs/vins/vins_node.h"
#include "vimot/features_t.hpp"
#include "vimot/ground_truth_t.hpp"
#include "vimot/imu_t.hpp"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("vins",
                         "MSCKF visual-inertial odometry: IMU + FEATURES in, VINS_STATE out.\n"
                         "Configured by config/vins.yaml (estimator options, calibration file,\n"
                         "channels, initialisation).",
                         /*config_required=*/true);
  process.args().add_option("perturb-seed", "N",
                            "start from ground truth perturbed with this seed (overrides init.perturb_seed)");
  process.args().add_option("max-wait", "SECONDS",
                            "process a queued camera frame after this much wall time without IMU", "0.5");
  if (!process.init(argc, argv)) return 0;

  vimot::VinsNodeOptions options;
  options.vio = vimot::eval::vio_options_from_config(process.config());
  const vimot::eval::VinsStartOptions start = vimot::eval::start_options_from_config(process.config());
  options.init_from_ground_truth = start.mode == vimot::estimator::InitMode::kGroundTruth;
  options.perturb_seed = start.perturb_seed;
  if (process.args().given("perturb-seed")) {
    options.perturb_seed = static_cast<uint64_t>(process.args().get_int("perturb-seed"));
  }
  options.publish_imu_rate = process.config().get_or<bool>("output.imu_rate", true);
  const double max_wait = process.args().get_double("max-wait");

  const std::string state_channel = process.channel("state", "VINS_STATE");
  vimot::VinsNode node(
      options, [&](const vimot::NavState& s) { process.publish(state_channel, vimot::to_lcm(s)); },
      [&](const vimot::VinsEvent& e) {
        switch (e.kind) {
          case vimot::VinsEvent::Kind::kInfo: vimot::log_info(e.message); break;
          case vimot::VinsEvent::Kind::kDropped: process.report_dropped(e.message); break;
          case vimot::VinsEvent::Kind::kError: process.report_error(e.message); break;
        }
      });

  using Clock = std::chrono::steady_clock;
  Clock::time_point last_imu_wall = Clock::now();
  process.subscribe<vimot::imu_t>(process.channel("imu", "IMU"), [&](const vimot::imu_t& m) {
    last_imu_wall = Clock::now();
    node.on_imu(vimot::from_lcm(m));
  });
  process.subscribe<vimot::features_t>(process.channel("features", "FEATURES"),
                                       [&](const vimot::features_t& m) { node.on_frame(vimot::from_lcm(m)); });
  if (options.init_from_ground_truth) {
    process.subscribe<vimot::ground_truth_t>(process.channel("ground_truth", "GROUND_TRUTH"),
                                             [&](const vimot::ground_truth_t& m) {
                                               node.on_ground_truth(vimot::from_lcm(m));
                                             });
  }
  vimot::log_info(options.init_from_ground_truth ? "waiting for GROUND_TRUTH to initialise"
                                                 : "initialising at rest from the IMU");
  // The bounded wait: if the IMU stream stops, queued frames are processed
  // with the data there is rather than held forever.
  const int status = process.run([&] {
    if (std::chrono::duration<double>(Clock::now() - last_imu_wall).count() > max_wait) node.flush();
  });
  node.flush();
  vimot::log_info("processed ", node.frames_processed(), " frames, ", node.resets(), " resets");
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

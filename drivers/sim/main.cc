// vimot-sim: the simulator as a sensor driver. Publishes IMU, FEATURES and
// GROUND_TRUTH on LCM at real time or any speed factor, or writes them
// straight into an LCM log file as fast as the CPU allows. The simulation
// itself is common/sim (no LCM); this file only converts and paces.
#include <variant>

#include "common/process/event_sink.h"
#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "common/sim/simulator.h"

namespace {

using vimot::log_info;

int run(int argc, const char* const* argv) {
  vimot::Process process("vimot-sim",
                         "Simulates a scenario (config/sim_*.yaml) and publishes IMU, FEATURES and\n"
                         "GROUND_TRUTH on LCM, paced by --speed, or writes them to an LCM log (--log).",
                         /*config_required=*/true);
  process.args().add_option("seed", "N", "noise seed (overrides the config's seed)");
  process.args().add_option("duration", "SECONDS", "simulate only this long (overrides the config)");
  vimot::add_sink_options(process.args());
  if (!process.init(argc, argv)) return 0;

  vimot::sim::SimConfig config = vimot::sim::from_config(process.config());
  if (process.args().given("seed")) config.seed = static_cast<uint64_t>(process.args().get_int("seed"));
  if (process.args().given("duration")) config.duration = process.args().get_double("duration");

  vimot::sim::Simulator sim(config);
  const std::string imu_channel = process.channel("imu", "IMU");
  const std::string features_channel = process.channel("features", "FEATURES");
  const std::string truth_channel = process.channel("ground_truth", "GROUND_TRUTH");

  const std::unique_ptr<vimot::EventSink> sink = vimot::make_sink(process, sim.start_utime());
  log_info("scenario ", vimot::sim::to_string(config.scenario), ", seed ", config.seed, ", ", sim.duration(),
           " s, path ", sim.path_length(), " m, ", sim.imu_sample_count(), " IMU samples, ",
           sim.camera_frame_count(), " camera frames",
           process.args().given("log") ? ", writing " + process.args().get("log") : "");

  int64_t counts[3] = {0, 0, 0};
  vimot::ProgressLog progress(sim.duration());
  while (!process.stop_requested()) {
    const std::optional<vimot::sim::SimEvent> event = sim.next();
    if (!event) break;
    int64_t utime = 0;
    if (const auto* imu = std::get_if<vimot::ImuData>(&*event)) {
      vimot::emit(*sink, imu_channel, vimot::to_lcm(*imu));
      utime = imu->utime;
      ++counts[0];
    } else if (const auto* frame = std::get_if<vimot::CameraFrame>(&*event)) {
      vimot::emit(*sink, features_channel, vimot::to_lcm(*frame));
      utime = frame->utime;
      ++counts[1];
    } else if (const auto* truth = std::get_if<vimot::GroundTruth>(&*event)) {
      vimot::emit(*sink, truth_channel, vimot::to_lcm(*truth));
      utime = truth->utime;
      ++counts[2];
    }
    progress.update(sim.sim_time(utime));
  }
  log_info(process.stop_requested() ? "stopped early: " : "done: ", counts[0], " on ", imu_channel, ", ", counts[1],
           " on ", features_channel, ", ", counts[2], " on ", truth_channel);
  vimot::linger(process, process.args().get_double("linger"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

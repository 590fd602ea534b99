// vimot-sim: the simulator as a sensor driver. Publishes IMU, FEATURES and
// GROUND_TRUTH on LCM at real time or any speed factor, or writes them
// straight into an LCM log file as fast as the CPU allows. With --render it
// publishes rendered camera images (and the true target mask and box)
// instead of FEATURES. The simulation and the rendering are common/sim (no
// LCM); this file only converts and paces.
#include <cmath>
#include <variant>

#include "common/process/event_sink.h"
#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "common/sim/renderer.h"
#include "common/sim/simulator.h"
#include "common/process/image_conversion.h"
#include "vimot/target_box_t.hpp"

namespace {

using vimot::log_info;

// The true box as a mask filter would report a perfect detection: raw =
// filtered, no coasting, zero covariance and velocity.
vimot::target_box_t to_box_msg(const vimot::sim::RenderedView& view) {
  vimot::target_box_t msg{};
  msg.utime = view.utime;
  msg.camera_id = static_cast<int8_t>(view.camera_id);
  msg.raw_valid = view.visible;
  msg.filtered_valid = view.visible;
  for (int k = 0; k < 4; ++k) msg.raw_box[k] = msg.filtered_box[k] = view.box(k);
  msg.frames_since_raw = 0;
  return msg;
}

int run(int argc, const char* const* argv) {
  vimot::Process process("vimot-sim",
                         "Simulates a scenario (config/sim_*.yaml) and publishes IMU, FEATURES and\n"
                         "GROUND_TRUTH on LCM, paced by --speed, or writes them to an LCM log (--log).\n"
                         "--render: rendered images on CAM_LEFT / CAM_RIGHT and the true target mask and\n"
                         "box (TARGET_MASK_TRUTH, TARGET_BOX_TRUTH) per camera instead of FEATURES.",
                         /*config_required=*/true);
  process.args().add_option("seed", "N", "noise seed (overrides the config's seed)");
  process.args().add_option("duration", "SECONDS", "simulate only this long (overrides the config)");
  vimot::add_sink_options(process.args());
  vimot::add_clock_file_option(process.args());
  process.args().add_option("outage-at", "SECONDS",
                            "send nothing from this time of the run (s after its start) for --outage-length: "
                            "the input outage of a driver killed and respawned then, reproducible in a log");
  process.args().add_option("outage-length", "SECONDS", "with --outage-at: how long nothing is sent");
  process.args().add_flag("render", "publish rendered images, target masks and boxes instead of FEATURES");
  process.args().add_flag("with-features", "with --render, publish FEATURES too");
  if (!process.init(argc, argv)) return 0;

  vimot::sim::SimConfig config = vimot::sim::from_config(process.config());
  if (process.args().given("seed")) config.seed = static_cast<uint64_t>(process.args().get_int("seed"));
  if (process.args().given("duration")) config.duration = process.args().get_double("duration");

  vimot::sim::Simulator sim(config);
  const std::string imu_channel = process.channel("imu", "IMU");
  const std::string features_channel = process.channel("features", "FEATURES");
  const std::string truth_channel = process.channel("ground_truth", "GROUND_TRUTH");
  const bool render = process.args().given("render");
  if (process.args().given("with-features") && !render) {
    throw vimot::ArgError("vimot-sim: --with-features needs --render");
  }
  const bool publish_features = !render || process.args().given("with-features");
  const std::string camera_channels[2] = {process.channel("cam_left", "CAM_LEFT"),
                                          process.channel("cam_right", "CAM_RIGHT")};
  const std::string mask_channel = process.channel("target_mask_truth", "TARGET_MASK_TRUTH");
  const std::string box_channel = process.channel("target_box_truth", "TARGET_BOX_TRUTH");
  std::unique_ptr<vimot::sim::Renderer> renderer;
  if (render) renderer = std::make_unique<vimot::sim::Renderer>(sim);

  // [outage_begin, outage_end): nothing sent (--outage-at, --outage-length).
  int64_t outage_begin = 0;
  int64_t outage_end = 0;
  if (process.args().given("outage-at") != process.args().given("outage-length")) {
    throw vimot::ArgError("vimot-sim: --outage-at and --outage-length go together");
  }
  if (process.args().given("outage-at")) {
    const double at = process.args().get_double("outage-at");
    const double length = process.args().get_double("outage-length");
    if (!(at >= 0.0 && at <= sim.duration()) || !(length > 0.0 && length <= sim.duration())) {
      throw vimot::ArgError("vimot-sim: the outage must start within the run (0 to " +
                            std::to_string(sim.duration()) + " s) and last a positive time no longer than it");
    }
    outage_begin = sim.start_utime() + static_cast<int64_t>(std::llround(at * 1e6));
    outage_end = outage_begin + static_cast<int64_t>(std::llround(length * 1e6));
  }

  int64_t resume_utime = sim.start_utime();
  const std::unique_ptr<vimot::EventSink> sink =
      vimot::make_sink(process, sim.start_utime(), sim.duration(), &resume_utime);
  log_info("scenario ", vimot::sim::to_string(config.scenario), ", seed ", config.seed, ", ", sim.duration(),
           " s, path ", sim.path_length(), " m, ", sim.imu_sample_count(), " IMU samples, ",
           sim.camera_frame_count(), " camera frames",
           process.args().given("log") ? ", writing " + process.args().get("log") : "");

  int64_t counts[4] = {0, 0, 0, 0};
  vimot::ProgressLog progress(sim.duration());
  while (!process.stop_requested()) {
    const std::optional<vimot::sim::SimEvent> event = sim.next();
    if (!event) break;
    // Restarted mid-run (--clock-file): what fell due meanwhile was never sent.
    const int64_t event_utime = std::visit([](const auto& e) { return e.utime; }, *event);
    if (event_utime < resume_utime) continue;
    if (event_utime >= outage_begin && event_utime < outage_end) continue;
    int64_t utime = 0;
    if (const auto* imu = std::get_if<vimot::ImuData>(&*event)) {
      vimot::emit(*sink, imu_channel, vimot::to_lcm(*imu));
      utime = imu->utime;
      ++counts[0];
    } else if (const auto* frame = std::get_if<vimot::CameraFrame>(&*event)) {
      if (publish_features) {
        vimot::emit(*sink, features_channel, vimot::to_lcm(*frame));
        ++counts[1];
      }
      if (renderer) {
        for (const vimot::sim::RenderedView& view : renderer->render(frame->utime)) {
          vimot::emit(*sink, camera_channels[view.camera_id], vimot::to_lcm_image(view.image, view.utime));
          vimot::emit(*sink, mask_channel, vimot::to_lcm_mask(view.mask, view.utime, view.camera_id));
          vimot::emit(*sink, box_channel, to_box_msg(view));
          ++counts[3];
        }
      }
      utime = frame->utime;
    } else if (const auto* truth = std::get_if<vimot::GroundTruth>(&*event)) {
      vimot::emit(*sink, truth_channel, vimot::to_lcm(*truth));
      utime = truth->utime;
      ++counts[2];
    }
    progress.update(sim.sim_time(utime));
  }
  log_info(process.stop_requested() ? "stopped early: " : "done: ", counts[0], " on ", imu_channel, ", ", counts[1],
           " on ", features_channel, ", ", counts[2], " on ", truth_channel,
           render ? ", " + std::to_string(counts[3]) + " rendered images (+ masks, boxes)" : std::string());
  vimot::linger(process, process.args().get_double("linger"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

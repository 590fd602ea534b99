// vimot-sim: the simulator as a sensor driver. Publishes IMU, FEATURES and
// GROUND_TRUTH on LCM at real time or any speed factor, or writes them
// straight into an LCM log file as fast as the CPU allows. With --render it
// publishes rendered camera images (and the true target mask and box)
// instead of FEATURES. The simulation and the rendering are common/sim (no
// LCM); this file only converts and paces.
#include <chrono>
#include <thread>
#include <variant>

#include <lcm/lcm-cpp.hpp>

#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "common/sim/renderer.h"
#include "common/sim/simulator.h"
#include "common/time/utime.h"
#include "vimot/image_t.hpp"
#include "vimot/mask_t.hpp"
#include "vimot/target_box_t.hpp"

namespace {

using vimot::log_info;

// The destination of the event stream: live LCM (paced) or a log file.
class EventSink {
 public:
  virtual ~EventSink() = default;
  virtual void write(const std::string& channel, int64_t utime, const void* data, int size) = 0;
};

class LogFileSink : public EventSink {
 public:
  explicit LogFileSink(const std::string& path) : log_(path, "w") {
    if (!log_.good()) throw std::runtime_error("cannot open '" + path + "' for writing");
  }
  void write(const std::string& channel, int64_t utime, const void* data, int size) override {
    lcm::LogEvent ev;
    ev.eventnum = eventnum_++;
    ev.timestamp = utime;  // message time, not wall time: same seed, same bytes
    ev.channel = channel;
    ev.datalen = size;
    ev.data = const_cast<void*>(data);
    if (log_.writeEvent(&ev) != 0) throw std::runtime_error("writing the log failed (disk full?)");
  }

 private:
  lcm::LogFile log_;
  int64_t eventnum_{0};
};

class LcmSink : public EventSink {
 public:
  LcmSink(vimot::Process& process, double speed, int64_t first_utime, double start_delay)
      : process_(process), speed_(speed), first_utime_(first_utime) {
    wall_start_ = std::chrono::steady_clock::now() + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                         std::chrono::duration<double>(start_delay));
    next_heartbeat_ = std::chrono::steady_clock::now();
  }
  void write(const std::string& channel, int64_t utime, const void* data, int size) override {
    if (speed_ > 0.0) {
      // Pacing only: the wall clock decides when to send, never what.
      const double sim_elapsed = vimot::utime_to_seconds(utime - first_utime_) / speed_;
      std::this_thread::sleep_until(wall_start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                      std::chrono::duration<double>(sim_elapsed)));
    }
    if (process_.lcm().publish(channel, data, static_cast<unsigned>(size)) != 0) {
      process_.report_error("publish on " + channel + " failed");
    } else {
      ++process_.counters().messages_out;
    }
    const auto now = std::chrono::steady_clock::now();
    if (now >= next_heartbeat_) {
      process_.publish_heartbeat();
      next_heartbeat_ = now + std::chrono::seconds(1);
    }
  }

 private:
  vimot::Process& process_;
  double speed_;
  int64_t first_utime_;
  std::chrono::steady_clock::time_point wall_start_;
  std::chrono::steady_clock::time_point next_heartbeat_;
};

vimot::image_t to_image_msg(const vimot::sim::RenderedView& view) {
  vimot::image_t msg;
  msg.utime = view.utime;
  msg.width = view.image.cols;
  msg.height = view.image.rows;
  msg.row_stride = view.image.cols;
  msg.pixelformat = vimot::image_t::PIXEL_FORMAT_GRAY;
  msg.data.assign(view.image.datastart, view.image.dataend);  // continuous CV_8UC1
  msg.size = static_cast<int32_t>(msg.data.size());
  msg.nmetadata = 0;
  return msg;
}

vimot::mask_t to_mask_msg(const vimot::sim::RenderedView& view) {
  vimot::mask_t msg;
  msg.utime = view.utime;
  msg.camera_id = static_cast<int8_t>(view.camera_id);
  msg.width = view.mask.cols;
  msg.height = view.mask.rows;
  msg.data.assign(view.mask.datastart, view.mask.dataend);
  msg.size = static_cast<int32_t>(msg.data.size());
  return msg;
}

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

template <typename Msg>
void emit(EventSink& sink, const std::string& channel, const Msg& msg) {
  std::vector<uint8_t> buffer(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
  sink.write(channel, msg.utime, buffer.data(), static_cast<int>(buffer.size()));
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
  process.args().add_option("speed", "FACTOR", "real-time factor when publishing; 0 = as fast as possible", "1");
  process.args().add_option("start-delay", "SECONDS", "wait before the first message (lets subscribers start)", "0");
  process.args().add_option("log", "FILE", "write an LCM log file instead of publishing (as fast as possible)");
  process.args().add_flag("render", "publish rendered images, target masks and boxes instead of FEATURES");
  process.args().add_flag("with-features", "with --render, publish FEATURES too");
  process.args().add_option("linger", "SECONDS",
                            "stay alive this long after the last message (lets consumers drain their queues)", "0");
  if (!process.init(argc, argv)) return 0;

  vimot::sim::SimConfig config = vimot::sim::from_config(process.config());
  if (process.args().given("seed")) config.seed = static_cast<uint64_t>(process.args().get_int("seed"));
  if (process.args().given("duration")) config.duration = process.args().get_double("duration");
  const double speed = process.args().get_double("speed");
  if (speed < 0.0) throw vimot::ArgError("vimot-sim: --speed must be >= 0, got " + process.args().get("speed"));

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

  std::unique_ptr<EventSink> sink;
  if (process.args().given("log")) {
    sink = std::make_unique<LogFileSink>(process.args().get("log"));
  } else {
    sink = std::make_unique<LcmSink>(process, speed, sim.start_utime(), process.args().get_double("start-delay"));
  }
  log_info("scenario ", vimot::sim::to_string(config.scenario), ", seed ", config.seed, ", ", sim.duration(),
           " s, path ", sim.path_length(), " m, ", sim.imu_sample_count(), " IMU samples, ",
           sim.camera_frame_count(), " camera frames",
           process.args().given("log") ? ", writing " + process.args().get("log") : "");

  int64_t counts[4] = {0, 0, 0, 0};
  int last_decile = 0;
  while (!process.stop_requested()) {
    const std::optional<vimot::sim::SimEvent> event = sim.next();
    if (!event) break;
    int64_t utime = 0;
    if (const auto* imu = std::get_if<vimot::ImuData>(&*event)) {
      emit(*sink, imu_channel, vimot::to_lcm(*imu));
      utime = imu->utime;
      ++counts[0];
    } else if (const auto* frame = std::get_if<vimot::CameraFrame>(&*event)) {
      if (publish_features) {
        emit(*sink, features_channel, vimot::to_lcm(*frame));
        ++counts[1];
      }
      if (renderer) {
        for (const vimot::sim::RenderedView& view : renderer->render(frame->utime)) {
          emit(*sink, camera_channels[view.camera_id], to_image_msg(view));
          emit(*sink, mask_channel, to_mask_msg(view));
          emit(*sink, box_channel, to_box_msg(view));
          ++counts[3];
        }
      }
      utime = frame->utime;
    } else if (const auto* truth = std::get_if<vimot::GroundTruth>(&*event)) {
      emit(*sink, truth_channel, vimot::to_lcm(*truth));
      utime = truth->utime;
      ++counts[2];
    }
    const int decile = static_cast<int>(10.0 * sim.sim_time(utime) / std::max(sim.duration(), 1e-9));
    if (decile > last_decile) {
      last_decile = decile;
      log_info("progress ", 10 * decile, "% (", sim.sim_time(utime), " s)");
    }
  }
  log_info(process.stop_requested() ? "stopped early: " : "done: ", counts[0], " on ", imu_channel, ", ", counts[1],
           " on ", features_channel, ", ", counts[2], " on ", truth_channel,
           render ? ", " + std::to_string(counts[3]) + " rendered images (+ masks, boxes)" : std::string());
  const auto linger_end = std::chrono::steady_clock::now() +
                          std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                              std::chrono::duration<double>(process.args().get_double("linger")));
  while (!process.stop_requested() && std::chrono::steady_clock::now() < linger_end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

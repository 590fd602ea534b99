// vimot-camera: one or two cameras (V4L2 devices through OpenCV) or video
// files, published as 8-bit grey image_t on CAM_LEFT (and CAM_RIGHT in
// stereo). Capture, stamping, pairing and reopening are CameraDriver (no
// LCM); this file paces, converts and reports.
#include <chrono>
#include <cstdlib>
#include <thread>

#include "common/process/event_sink.h"
#include "common/process/image_conversion.h"
#include "common/process/process.h"
#include "common/time/utime.h"
#include "drivers/camera/camera_config.h"

namespace {

using Clock = std::chrono::steady_clock;

void report_counters(vimot::Process& process, const vimot::camera::CameraCounters& c) {
  process.counters().messages_in = c.frames[0] + c.frames[1];
  process.counters().dropped = c.non_increasing[0] + c.non_increasing[1] + c.unpaired[0] + c.unpaired[1];
  for (const auto& [name, value] : vimot::camera::named_counters(c)) process.set_counter(name, value);
}

int run(int argc, const char* const* argv) {
  vimot::Process process("vimot-camera",
                         "One camera (mode: mono) or two paired by time (mode: stereo): V4L2 devices or video\n"
                         "files through OpenCV, published as 8-bit grey image_t on CAM_LEFT / CAM_RIGHT.\n"
                         "Configured by config/camera.yaml (sources, image, timing, reopen, channels).\n"
                         "--speed paces files stamped at their frame rate; --log writes an LCM log instead.",
                         /*config_required=*/true);
  vimot::add_sink_options(process.args());
  if (!process.init(argc, argv)) return 0;

  const vimot::camera::CameraConfig config = vimot::camera::camera_config_from(process.config());
  // OpenCV's V4L2 backend waits this long (default 10 s) for a frame and
  // reads it once, at the first capture: set before any device opens.
  setenv("OPENCV_VIDEOIO_V4L_SELECT_TIMEOUT", std::to_string(config.stall_timeout_s).c_str(), 1);
  const auto log = [](const std::string& text) { vimot::log_info(text); };
  std::vector<vimot::camera::SourceOpener> openers;
  for (std::size_t i = 0; i < config.sources.size(); ++i) openers.push_back(source_opener(config, i, log));
  vimot::camera::CameraDriver driver(config.driver, std::move(openers), vimot::wall_clock_utime, log);
  const std::string left_channel = process.channel("cam_left", "CAM_LEFT");
  const std::string right_channel = process.channel("cam_right", "CAM_RIGHT");

  // Files stamped at their rate are paced by utime (--speed) or logged
  // (--log); live stamps leave as they are captured.
  const bool paced = driver.deterministic();
  const std::unique_ptr<vimot::EventSink> sink = paced || process.args().given("log")
                                                     ? vimot::make_sink(process, config.driver.file_start_utime)
                                                     : std::make_unique<vimot::LcmSink>(process, 0.0, 0, 0.0);
  // A host-stamped file is read at its frame rate, as a camera would deliver it.
  const double read_period_s = paced ? 0.0 : driver.file_period_s();
  auto next_read = Clock::now();
  auto next_heartbeat = Clock::now();
  while (!process.stop_requested() && !driver.finished()) {
    if (read_period_s > 0.0) {
      std::this_thread::sleep_until(next_read);
      next_read += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(read_period_s));
    }
    const std::vector<vimot::camera::OutputFrame> frames = driver.step();
    report_counters(process, driver.counters());
    for (const vimot::camera::OutputFrame& f : frames) {
      vimot::emit(*sink, left_channel, vimot::to_lcm_image(f.left, f.utime));
      if (!f.right.empty()) vimot::emit(*sink, right_channel, vimot::to_lcm_image(f.right, f.utime));
    }
    if (frames.empty() && driver.reopening()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    // The paced sink sends the heartbeat itself while it writes.
    if (!paced && Clock::now() >= next_heartbeat) {
      process.publish_heartbeat();
      next_heartbeat = Clock::now() + std::chrono::seconds(1);
    }
  }
  report_counters(process, driver.counters());
  if (!process.args().given("log")) process.publish_heartbeat();  // the final counts
  const vimot::camera::CameraCounters& c = driver.counters();
  vimot::log_info(
      driver.finished() ? "end of file: " : "stopping: ", c.published, config.driver.stereo ? " pairs" : " images",
      " published, ", c.frames[0] + c.frames[1], " frames read, ", c.unpaired[0] + c.unpaired[1], " unpaired, ",
      c.non_increasing[0] + c.non_increasing[1], " non-increasing, ", c.stalls, " stalls, ", c.reopens, " reopens");
  vimot::linger(process, process.args().get_double("linger"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

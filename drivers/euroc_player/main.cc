// vimot-euroc-player: an ASL/EuRoC dataset folder as a sensor driver.
// Publishes IMU, CAM_LEFT, CAM_RIGHT (grey image_t) and GROUND_TRUTH (when
// the dataset has it) on LCM at real time or any speed factor, or writes them
// straight into an LCM log file as fast as the CPU allows. Reading and
// checking the dataset is EurocPlayer (no LCM); this file only converts and
// paces.
#include <variant>

#include "common/process/event_sink.h"
#include "common/process/image_conversion.h"
#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "common/time/utime.h"
#include "drivers/euroc_player/euroc_player.h"

namespace {

using vimot::log_info;

int run(int argc, const char* const* argv) {
  vimot::Process process("vimot-euroc-player",
                         "Plays an ASL/EuRoC dataset folder (mav0/ with cam0, cam1, imu0): publishes IMU,\n"
                         "CAM_LEFT, CAM_RIGHT and GROUND_TRUTH (if present) on LCM, paced by --speed, or\n"
                         "writes them to an LCM log (--log). Channel names from the config's channels:\n"
                         "imu, cam_left, cam_right, ground_truth.");
  process.args().add_option("dataset", "DIR", "ASL dataset folder (holding mav0/, or mav0/ itself); required");
  process.args().add_option("groundtruth", "FILE",
                            "ground-truth CSV (time[ns],p,q(w,x,y,z)[,v[,bg,ba]]); default: "
                            "mav0/state_groundtruth_estimate0/data.csv if present");
  process.args().add_flag("no-groundtruth", "do not publish ground truth");
  process.args().add_option("start", "SECONDS", "skip this long after the first stereo pair", "0");
  process.args().add_option("duration", "SECONDS", "play this long from --start; 0 = to the last stereo pair", "0");
  process.args().add_option("imu-lead", "SECONDS",
                            "IMU and ground truth from this long before the first played pair", "1");
  vimot::add_sink_options(process.args());
  if (!process.init(argc, argv)) return 0;
  if (!process.args().given("dataset")) throw vimot::ArgError("vimot-euroc-player: --dataset DIR is required");

  vimot::euroc::PlayerOptions options;
  options.dataset = process.args().get("dataset");
  if (process.args().given("groundtruth")) options.groundtruth_file = process.args().get("groundtruth");
  options.use_groundtruth = !process.args().flag("no-groundtruth");
  options.start_s = process.args().get_double("start");
  options.duration_s = process.args().get_double("duration");
  options.imu_lead_s = process.args().get_double("imu-lead");
  vimot::euroc::EurocPlayer player(options);
  const vimot::euroc::PlayerSummary& s = player.summary();

  const std::string imu_channel = process.channel("imu", "IMU");
  const std::string left_channel = process.channel("cam_left", "CAM_LEFT");
  const std::string right_channel = process.channel("cam_right", "CAM_RIGHT");
  const std::string truth_channel = process.channel("ground_truth", "GROUND_TRUTH");

  const std::unique_ptr<vimot::EventSink> sink = vimot::make_sink(process, player.first_utime());
  log_info(s.mav0, ": ", s.stereo_pairs, " stereo pairs ", s.width, "x", s.height, " over ",
           vimot::utime_to_seconds(s.span_end_utime - s.span_start_utime), " s, ", s.imu_samples, " IMU samples, ",
           s.groundtruth_poses, " ground-truth poses",
           s.groundtruth_file.empty() ? " (no ground truth)" : " from " + s.groundtruth_file,
           process.args().given("log") ? ", writing " + process.args().get("log") : "");
  if (s.unpaired_left + s.unpaired_right > 0) {
    log_info("skipped frames listed by one camera only: ", s.unpaired_left, " cam0, ", s.unpaired_right, " cam1");
  }

  int64_t counts[3] = {0, 0, 0};
  vimot::ProgressLog progress(vimot::utime_to_seconds(player.last_utime() - player.first_utime()));
  while (!process.stop_requested()) {
    const std::optional<vimot::euroc::PlayerEvent> event = player.next();
    if (!event) break;
    int64_t utime = 0;
    if (const auto* imu = std::get_if<vimot::ImuData>(&*event)) {
      vimot::emit(*sink, imu_channel, vimot::to_lcm(*imu));
      utime = imu->utime;
      ++counts[0];
    } else if (const auto* frame = std::get_if<vimot::euroc::StereoFrame>(&*event)) {
      const vimot::euroc::StereoImages images = player.load_images(*frame);
      vimot::emit(*sink, left_channel, vimot::to_lcm_image(images.left, frame->utime));
      vimot::emit(*sink, right_channel, vimot::to_lcm_image(images.right, frame->utime));
      utime = frame->utime;
      ++counts[1];
    } else if (const auto* truth = std::get_if<vimot::GroundTruth>(&*event)) {
      vimot::emit(*sink, truth_channel, vimot::to_lcm(*truth));
      utime = truth->utime;
      ++counts[2];
    }
    progress.update(vimot::utime_to_seconds(utime - player.first_utime()));
  }
  log_info(process.stop_requested() ? "stopped early: " : "done: ", counts[0], " on ", imu_channel, ", ", counts[1],
           " on ", left_channel, " and ", right_channel, ", ", counts[2], " on ", truth_channel);
  vimot::linger(process, process.args().get_double("linger"));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

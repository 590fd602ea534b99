// vimot-bench-feature-tracker: time per stereo pair of the feature tracker
// (common/frontend) on one core over an ASL/EuRoC folder (mean, median,
// p95 of FeatureTracker::track's thread CPU time, which a machine shared
// with other jobs does not inflate, and of its wall time), with the tracking quality
// figures of that run: static features per frame, median track length and
// median stereo epipolar error against the folder's own calibration.
// Images are decoded before timing, so the figures are the tracker's alone.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <numeric>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/camera/camera_model.h"
#include "common/config/config.h"
#include "common/eval/machine.h"
#include "common/frontend/asl_stereo_folder.h"
#include "common/frontend/feature_tracker.h"
#include "common/frontend/tracking_stats.h"
#include "common/process/arg_parser.h"
#include "common/time/utime.h"

namespace {

using namespace vimot;

struct Summary {
  double mean, median, p95, max;
};

Summary summarize(const std::vector<double>& v) {
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end());
  const std::size_t i95 =
      std::min(sorted.size() - 1, static_cast<std::size_t>(0.95 * static_cast<double>(sorted.size())));
  return {std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size()), frontend::median(v), sorted[i95],
          sorted.back()};
}

std::string default_folder() {
  const char* root = std::getenv("VIMOT_DATA_DIR");
  return root ? std::string(root) + "/euroc_v101_micro/mav0" : "";
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-feature-tracker",
                 "Feature tracker time per stereo pair (wall ms of FeatureTracker::track on one core:\n"
                 "mean, median, p95) over an ASL/EuRoC mav0 folder, and the tracking quality of the run:\n"
                 "static features per frame (min after the first), median track length (frames), median\n"
                 "stereo epipolar error (px, undistorted, from the folder's sensor.yaml calibration).");
  args.add_option("folder", "DIR", "ASL mav0 folder (default: $VIMOT_DATA_DIR/euroc_v101_micro/mav0)",
                  default_folder());
  args.add_option("config", "FILE", "tracker options: the `tracker:` section of this file (default: built-in)");
  args.add_option("repeat", "N", "passes over the images (timing only; quality from the first pass)", "5");
  args.add_flag("mono", "track cam0 only");
  args.add_option("box", "X,Y,W,H",
                  "a fixed target box [x_min, y_min, width, height] (px) in both images, to time the ORB target path");
  if (!args.parse(argc, argv)) return 0;
  const std::string folder = args.get("folder");
  if (folder.empty()) throw ArgError("no --folder given and VIMOT_DATA_DIR is not set");
  const long long repeat = args.get_int("repeat");
  if (repeat < 1) throw ArgError("--repeat must be >= 1");

  std::optional<frontend::Box> box;
  if (args.given("box")) {
    frontend::Box b;
    char extra = 0;
    if (std::sscanf(args.get("box").c_str(), "%lf,%lf,%lf,%lf%c", &b.x_min, &b.y_min, &b.width, &b.height, &extra) !=
        4) {
      throw ArgError("--box must be X,Y,W,H, got '" + args.get("box") + "'");
    }
    box = b;
  }
  frontend::FeatureTrackerOptions options;
  if (args.given("config")) {
    options = frontend::FeatureTrackerOptions::from_config(Config::load_file(args.get("config")), "tracker");
  }
  std::vector<CameraCalibration> cameras = load_euroc_cameras(folder);
  if (args.flag("mono")) cameras.resize(1);
  const bool stereo = cameras.size() == 2;

  std::vector<frontend::AslStereoPair> pairs = frontend::read_asl_stereo_pairs(folder);
  std::vector<int64_t> utimes;
  std::vector<cv::Mat> left, right;
  for (const frontend::AslStereoPair& p : pairs) {
    if (stereo && p.right_path.empty()) continue;
    left.push_back(cv::imread(p.left_path, cv::IMREAD_UNCHANGED));
    right.push_back(stereo ? cv::imread(p.right_path, cv::IMREAD_UNCHANGED) : cv::Mat());
    if (left.back().empty() || (stereo && right.back().empty())) {
      throw std::runtime_error("cannot decode " + p.left_path + " / " + p.right_path);
    }
    utimes.push_back(p.timestamp_ns / 1000);
  }
  if (utimes.size() < 2) throw std::runtime_error(folder + ": fewer than 2 usable frames");

  cv::setNumThreads(1);
  std::vector<double> wall_ms, cpu_ms;
  frontend::TrackerTiming stage_sum;
  frontend::TrackingFigures figures;
  for (long long pass = 0; pass < repeat; ++pass) {
    frontend::FeatureTracker tracker(options, cameras);
    frontend::TrackingStats stats(cameras);
    for (std::size_t i = 0; i < utimes.size(); ++i) {
      const double c0 = thread_cpu_ms();
      const auto t0 = std::chrono::steady_clock::now();
      const CameraFrame frame = tracker.track(utimes[i], left[i], right[i], box, stereo ? box : std::nullopt);
      const auto t1 = std::chrono::steady_clock::now();
      cpu_ms.push_back(thread_cpu_ms() - c0);
      wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      const frontend::TrackerTiming& st = tracker.last_timing();
      stage_sum.preprocess_ms += st.preprocess_ms;
      stage_sum.static_temporal_ms += st.static_temporal_ms;
      stage_sum.detect_ms += st.detect_ms;
      stage_sum.static_stereo_ms += st.static_stereo_ms;
      stage_sum.target_ms += st.target_ms;
      stage_sum.total_ms += st.total_ms;
      if (pass == 0) stats.add(frame);
    }
    if (pass == 0) figures = stats.figures();
  }
  const Summary cpu = summarize(cpu_ms), wall = summarize(wall_ms);

  const eval::MachineInfo machine = eval::machine_info();
  std::printf("machine: %s, %d hardware threads; OpenCV threads: %d\n", machine.cpu_model.c_str(), machine.nproc,
              cv::getNumThreads());
  std::printf("folder: %s (%zu %s frames of %dx%d, %lld passes)\n", folder.c_str(), utimes.size(),
              stereo ? "stereo" : "mono", cameras[0].width, cameras[0].height, repeat);
  const char* unit = stereo ? "stereo pair" : "frame";
  std::printf("CPU time per %s: mean %.2f ms, median %.2f ms, p95 %.2f ms, max %.2f ms\n", unit, cpu.mean, cpu.median,
              cpu.p95, cpu.max);
  std::printf(
      "wall time per %s: mean %.2f ms, median %.2f ms, p95 %.2f ms, max %.2f ms (includes waiting for the "
      "CPU on a shared machine)\n",
      unit, wall.mean, wall.median, wall.p95, wall.max);
  // Stage shares of the wall time (their ratios hold on a loaded machine).
  std::printf(
      "profile (share of wall time): preprocess %.0f %%, KLT frame to frame + RANSAC %.0f %%, FAST grid "
      "%.0f %%, stereo KLT + RANSAC %.0f %%, target %.0f %%\n",
      100.0 * stage_sum.preprocess_ms / stage_sum.total_ms, 100.0 * stage_sum.static_temporal_ms / stage_sum.total_ms,
      100.0 * stage_sum.detect_ms / stage_sum.total_ms, 100.0 * stage_sum.static_stereo_ms / stage_sum.total_ms,
      100.0 * stage_sum.target_ms / stage_sum.total_ms);
  if (box) std::printf("target features per frame (cam0, ORB in the box): mean %.1f\n", figures.mean_target_per_frame);
  std::printf("static features per frame (cam0): min %d after the first, mean %.1f\n", figures.min_static_per_frame,
              figures.mean_static_per_frame);
  std::printf("median track length: %.1f frames\n", figures.median_track_length);
  if (stereo) {
    std::printf("median stereo epipolar error: %.3f px over %zu stereo observations\n", figures.median_epipolar_px,
                figures.stereo_observations);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-feature-tracker", argc, argv, run); }

// vimot-bench-mask-filter: time per mask of the mask filter
// (common/segmentation: opening, largest blob, box Kalman filter) on one
// core, over the rendered paper scenario's 752x480 target masks corrupted
// with false-positive specks (the masks are rendered before timing, so the
// figures are the filter's alone). Thread CPU time, which other jobs on a
// shared machine do not inflate, and wall time; also for empty masks (no
// detection, the filter coasting).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/config/config.h"
#include "common/eval/machine.h"
#include "common/process/arg_parser.h"
#include "common/segmentation/mask_filter.h"
#include "common/sim/renderer.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"
#include "common/time/utime.h"

namespace {

using namespace vimot;

void print_times(const char* what, std::vector<double> cpu, std::vector<double> wall) {
  for (std::vector<double>* v : {&cpu, &wall}) std::sort(v->begin(), v->end());
  const auto at = [](const std::vector<double>& v, double q) {
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  };
  const auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  };
  std::printf("%s: CPU per mask mean %.3f ms, median %.3f ms, p95 %.3f ms; wall mean %.3f ms, median %.3f ms\n", what,
              mean(cpu), at(cpu, 0.5), at(cpu, 0.95), mean(wall), at(wall, 0.5));
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-mask-filter",
                 "Mask filter time per 752x480 mask on one core (CPU and wall ms: mean, median, p95)\n"
                 "over the rendered paper scenario's target masks with false-positive specks, and over\n"
                 "empty masks. Run from the source tree (or give the config paths).");
  args.add_option("sim-config", "FILE", "simulator config", "config/sim_paper.yaml");
  args.add_option("config", "FILE", "mask filter config (its `filter:` section)", "config/mask_filter.yaml");
  args.add_option("frames", "N", "rendered stereo frames (masks: 2 per frame)", "50");
  args.add_option("repeat", "N", "passes over the masks", "10");
  if (!args.parse(argc, argv)) return 0;
  const long long frames = args.get_int("frames"), repeat = args.get_int("repeat");
  if (frames < 1 || repeat < 1) throw ArgError("--frames and --repeat must be >= 1");
  const segmentation::MaskFilterOptions options =
      segmentation::MaskFilterOptions::from_config(Config::load_file(args.get("config")), "filter");
  const sim::SimConfig sim_config = sim::from_config(Config::load_file(args.get("sim-config")));
  const sim::Simulator sim(sim_config);
  const sim::Renderer renderer(sim);
  if (frames > sim.camera_frame_count()) throw ArgError("--frames exceeds the scenario's camera frames");

  std::mt19937 rng(1);
  std::vector<cv::Mat> masks[2];
  std::vector<int64_t> utimes;
  for (long long k = 0; k < frames; ++k) {
    utimes.push_back(sim.camera_utime(static_cast<int>(k)));
    for (const sim::RenderedView& v : renderer.render(utimes.back())) {
      cv::Mat m = v.mask.clone();
      std::uniform_int_distribution<int> u(0, m.cols - 5), r(0, m.rows - 5), s(1, 4);
      for (int i = 0; i < 20; ++i) m(cv::Rect(u(rng), r(rng), s(rng), s(rng))).setTo(255);
      masks[v.camera_id].push_back(m);
    }
  }
  cv::setNumThreads(1);
  const auto time_masks = [&](bool empty, std::vector<double>* cpu, std::vector<double>* wall) {
    const cv::Mat none = cv::Mat::zeros(masks[0][0].size(), CV_8UC1);
    for (long long pass = 0; pass < repeat; ++pass) {
      for (int cam = 0; cam < 2; ++cam) {
        segmentation::MaskFilter filter(options);
        for (std::size_t i = 0; i < utimes.size(); ++i) {
          const double c0 = thread_cpu_ms();
          const auto t0 = std::chrono::steady_clock::now();
          filter.process(utimes[i], empty ? none : masks[cam][i]);
          wall->push_back(
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
          cpu->push_back(thread_cpu_ms() - c0);
        }
      }
    }
  };
  std::vector<double> cpu, wall, cpu_empty, wall_empty;
  time_masks(false, &cpu, &wall);
  time_masks(true, &cpu_empty, &wall_empty);

  const eval::MachineInfo machine = eval::machine_info();
  std::printf("machine: %s, %d hardware threads; OpenCV threads: %d\n", machine.cpu_model.c_str(), machine.nproc,
              cv::getNumThreads());
  std::printf("masks: %zu per camera, %dx%d, 2 cameras, %lld passes; erode %d px, dilate %d px\n", utimes.size(),
              masks[0][0].cols, masks[0][0].rows, repeat, options.morphology.erode_kernel_px,
              options.morphology.dilate_kernel_px);
  print_times("target masks with specks", cpu, wall);
  print_times("empty masks", cpu_empty, wall_empty);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-mask-filter", argc, argv, run); }

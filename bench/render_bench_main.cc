// vimot-bench-render: time of the rendered simulator (sim::Renderer) per
// frame (all cameras: a stereo pair, or one mono image) on one core: thread
// CPU ms, mean / median / p95 / max, over frames spread evenly over each
// scenario's run. For reference it counts FAST corners (threshold 20,
// non-max suppression) per image, off and on the target mask, outside the
// timing. Optionally writes the first timed frame's images and masks as PNG
// files to look at.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/eval/machine.h"
#include "common/eval/metrics.h"
#include "common/process/arg_parser.h"
#include "common/sim/renderer.h"
#include "common/sim/sim_config.h"
#include "common/time/utime.h"

namespace {

using namespace vimot;

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-render",
                 "Rendered-simulator time per frame (all cameras of the scenario: a stereo pair or one\n"
                 "mono image) on one core, thread CPU ms (mean, median, p95, max), over --frames frames\n"
                 "spread evenly over each scenario's run. Construction (textures, rays) is timed apart.\n"
                 "FAST: mean corners per image (threshold 20, non-max suppression), static / on the target.");
  args.add_option("configs", "FILES", "comma-separated simulator configs",
                  "config/sim_paper.yaml,config/sim_mono.yaml");
  args.add_option("frames", "N", "frames timed per scenario", "200");
  args.add_option("seed", "N", "simulator seed", "1");
  args.add_option("png", "PREFIX", "write the first timed frame as PREFIX<scenario>_cam<k>.png (+ _mask)");
  if (!args.parse(argc, argv)) return 0;
  const int frames = static_cast<int>(args.get_int("frames"));
  if (frames < 1) throw ArgError("--frames must be >= 1, got " + args.get("frames"));
  cv::setNumThreads(1);  // one core, whatever OpenCV would use

  const eval::MachineInfo machine = eval::machine_info();
  std::printf("vimot-bench-render: %d frames per scenario, seed %s, one thread (cv::setNumThreads(1))\n"
              "machine: %d CPUs, %s\n\n",
              frames, args.get("seed").c_str(), machine.nproc, machine.cpu_model.c_str());
  std::printf("%-10s %4s %9s %8s | %7s %7s %7s %7s | %6s %6s\n", "scenario", "cams", "size", "setup s", "mean",
              "median", "p95", "max", "FAST", "target");
  std::printf("%-10s %4s %9s %8s | %31s | %13s\n", "", "", "", "", "CPU ms per frame", "per image");
  for (const std::string& file : split_comma_list(args.get("configs"))) {
    sim::SimConfig config = sim::from_config(Config::load_file(file));
    config.seed = static_cast<uint64_t>(args.get_int("seed"));
    const sim::Simulator sim(config);
    const auto setup_start = std::chrono::steady_clock::now();
    const sim::Renderer renderer(sim);
    const double setup_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    std::vector<double> ms;
    double fast_static = 0.0, fast_target = 0.0;
    int images = 0;
    const int64_t n = sim.camera_frame_count();
    for (int k = 0; k < frames; ++k) {
      const int64_t frame = frames == 1 ? 0 : (n - 1) * k / (frames - 1);
      const int64_t utime = sim.camera_utime(frame);
      const double start = thread_cpu_ms();
      const std::vector<sim::RenderedView> views = renderer.render(utime);
      ms.push_back(thread_cpu_ms() - start);
      for (const sim::RenderedView& v : views) {
        std::vector<cv::KeyPoint> corners;
        cv::FAST(v.image, corners, 20, true);
        for (const cv::KeyPoint& c : corners) {
          const bool on_target = v.mask.at<uint8_t>(cvRound(c.pt.y), cvRound(c.pt.x)) != 0;
          (on_target ? fast_target : fast_static) += 1.0;
        }
        ++images;
      }
      if (k == 0 && args.given("png")) {
        for (const sim::RenderedView& v : views) {
          const std::string stem =
              args.get("png") + sim::to_string(config.scenario) + "_cam" + std::to_string(v.camera_id);
          if (!cv::imwrite(stem + ".png", v.image) || !cv::imwrite(stem + "_mask.png", v.mask)) {
            throw std::runtime_error("cannot write '" + stem + ".png'");
          }
        }
      }
    }
    const eval::TimingStats t = eval::timing_stats(ms);
    const CameraCalibration& c0 = config.camera.calibrations.at(0);
    std::printf("%-10s %4zu %4dx%-4d %8.2f | %7.2f %7.2f %7.2f %7.2f | %6.0f %6.0f\n",
                sim::to_string(config.scenario).c_str(), config.camera.calibrations.size(), c0.width, c0.height,
                setup_s, t.mean_ms, t.median_ms, t.p95_ms, t.max_ms, fast_static / images, fast_target / images);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-render", argc, argv, run); }

// vimot-bench-segmenter: the shipped segmentation network (OnnxSegmenter,
// OpenCV dnn) on one core: thread CPU ms per image (resize, network,
// upsampling, threshold), over rendered frames spread evenly over each
// scenario's run, and the masks' quality against the renderer's exact masks
// at full resolution (target IoU over all pixels, mean per-image IoU, pixel
// accuracy), outside the timing.
#include <opencv2/core.hpp>

#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/eval/machine.h"
#include "common/eval/metrics.h"
#include "common/process/arg_parser.h"
#include "common/segmentation/segmenter.h"
#include "common/sim/renderer.h"
#include "common/sim/sim_config.h"
#include "common/time/utime.h"

namespace {

using namespace vimot;

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-segmenter",
                 "The shipped segmentation network on one core: CPU ms per image (mean, median, p95,\n"
                 "max) over --frames rendered frames of each scenario, and its masks against the\n"
                 "renderer's exact ones at full resolution: IoU of the target over all pixels, mean\n"
                 "IoU per image with the target, pixel accuracy.");
  args.add_option("config", "FILE", "segmenter config (its onnx section)", "config/segmenter.yaml");
  args.add_option("sim", "FILE", "simulator config (repeatable as a comma list)", "config/sim_paper.yaml");
  args.add_option("frames", "N", "frames per scenario", "50");
  args.add_option("seed", "N", "simulator seed", "1");
  if (!args.parse(argc, argv)) return 0;
  const int frames = static_cast<int>(args.get_int("frames"));
  if (frames < 2) throw ArgError("--frames must be >= 2, got " + args.get("frames"));
  cv::setNumThreads(1);

  const segmentation::OnnxSegmenterOptions options =
      segmentation::OnnxSegmenterOptions::from_config(Config::load_file(args.get("config")), "onnx");
  segmentation::OnnxSegmenter segmenter(options);
  const eval::MachineInfo machine = eval::machine_info();
  std::printf("vimot-bench-segmenter: %s, input %dx%d, one thread (cv::setNumThreads(1))\nmachine: %d CPUs, %s\n\n",
              options.model_file.c_str(), options.input_width, options.input_height, machine.nproc,
              machine.cpu_model.c_str());
  std::printf("%-24s %6s | %7s %7s %7s %7s | %7s %7s %8s\n", "scenario", "images", "mean", "median", "p95", "max",
              "IoU", "mIoU/im", "accuracy");
  const std::string sims = args.get("sim");
  std::size_t start = 0;
  while (start < sims.size()) {
    const std::size_t comma = sims.find(',', start);
    const std::string file = sims.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    start = comma == std::string::npos ? sims.size() : comma + 1;
    sim::SimConfig config = sim::from_config(Config::load_file(file));
    config.seed = static_cast<uint64_t>(args.get_int("seed"));
    const sim::Simulator sim(config);
    const sim::Renderer renderer(sim);
    std::vector<double> ms, image_iou;
    double tp = 0, fp = 0, fn = 0, pixels = 0;
    const int64_t n = sim.camera_frame_count();
    for (int k = 0; k < frames; ++k) {
      for (const sim::RenderedView& v : renderer.render(sim.camera_utime((n - 1) * k / (frames - 1)))) {
        const double t0 = thread_cpu_ms();
        const cv::Mat mask = segmenter.segment(v.image);
        ms.push_back(thread_cpu_ms() - t0);
        const cv::Mat pred = mask != 0, truth = v.mask != 0;
        const double i = cv::countNonZero(pred & truth), u = cv::countNonZero(pred | truth);
        tp += i;
        fp += cv::countNonZero(pred & ~truth);
        fn += cv::countNonZero(~pred & truth);
        pixels += static_cast<double>(mask.total());
        if (v.visible) image_iou.push_back(i / u);
      }
    }
    double mean_iou = 0.0;
    for (double x : image_iou) mean_iou += x / static_cast<double>(image_iou.size());
    const eval::TimingStats t = eval::timing_stats(ms);
    std::printf("%-24s %6zu | %7.2f %7.2f %7.2f %7.2f | %7.3f %7.3f %7.2f%%\n", file.c_str(), ms.size(), t.mean_ms,
                t.median_ms, t.p95_ms, t.max_ms, tp / (tp + fp + fn), mean_iou, 100.0 * (pixels - fp - fn) / pixels);
    std::fflush(stdout);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-segmenter", argc, argv, run); }

// vimot-bench-camera: the camera driver's cost per stereo pair (decode,
// grey conversion, stamping, pairing: CameraDriver::step over two video
// files), process CPU ms: FFmpeg may decode on threads of its own, which a
// thread clock would miss. The frames are the rendered paper scenario's
// 752x480 stereo images, written as BGR video with each codec before the
// timing, so the figures are the driver's (decoding included, as for a USB
// camera delivering MJPG) and not the renderer's.
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/eval/machine.h"
#include "common/eval/metrics.h"
#include "common/process/arg_parser.h"
#include "common/sim/renderer.h"
#include "common/sim/sim_config.h"
#include "drivers/camera/camera_driver.h"

namespace {

using namespace vimot;

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-camera",
                 "Camera driver process CPU ms per stereo pair (mean, median, p95, max): two\n"
                 "752x480 BGR videos of the rendered paper scenario, per codec, read, converted to\n"
                 "grey and paired by CameraDriver. Run from the source tree (or give --sim).");
  args.add_option("sim", "FILE", "simulator config", "config/sim_paper.yaml");
  args.add_option("frames", "N", "stereo frames", "200");
  args.add_option("dir", "DIR", "folder for the videos (removed afterwards)", "/tmp/vimot_bench_camera");
  if (!args.parse(argc, argv)) return 0;
  const int frames = static_cast<int>(args.get_int("frames"));
  if (frames < 1) throw ArgError("--frames must be >= 1, got " + args.get("frames"));
  const sim::Simulator sim(sim::from_config(Config::load_file(args.get("sim"))));
  const sim::Renderer renderer(sim);
  if (frames > sim.camera_frame_count()) throw ArgError("--frames exceeds the scenario's camera frames");
  const std::string dir = args.get("dir");
  std::filesystem::create_directories(dir);

  struct Codec {
    const char* name;
    int fourcc;
  };
  const Codec codecs[] = {{"MJPG", cv::VideoWriter::fourcc('M', 'J', 'P', 'G')},
                          {"FFV1", cv::VideoWriter::fourcc('F', 'F', 'V', '1')}};
  std::vector<cv::VideoWriter> writers;
  cv::Size size;
  for (int k = 0; k < frames; ++k) {
    for (const sim::RenderedView& v : renderer.render(sim.camera_utime(k))) {
      if (writers.empty()) size = v.image.size();
      while (writers.size() < 4) {
        const std::size_t i = writers.size();
        const std::string path = dir + "/" + codecs[i / 2].name + (i % 2 == 0 ? "_left.avi" : "_right.avi");
        writers.emplace_back(path, cv::CAP_FFMPEG, codecs[i / 2].fourcc, 20.0, size, true);
        if (!writers.back().isOpened()) throw std::runtime_error("cannot write " + path);
      }
      cv::Mat bgr;
      cv::cvtColor(v.image, bgr, cv::COLOR_GRAY2BGR);
      writers[static_cast<std::size_t>(v.camera_id)].write(bgr);
      writers[static_cast<std::size_t>(2 + v.camera_id)].write(bgr);
    }
  }
  writers.clear();  // closes the files

  cv::setNumThreads(1);
  const eval::MachineInfo machine = eval::machine_info();
  std::printf(
      "vimot-bench-camera: %d stereo pairs %dx%d, cv::setNumThreads(1), process CPU time\nmachine: %d CPUs, %s\n\n",
      frames, size.width, size.height, machine.nproc, machine.cpu_model.c_str());
  std::printf("%-6s %6s | %7s %7s %7s %7s  (CPU ms per pair)\n", "codec", "pairs", "mean", "median", "p95", "max");
  for (const Codec& codec : codecs) {
    camera::CameraOptions options;
    options.stereo = true;
    options.width = size.width;
    options.height = size.height;
    std::vector<camera::SourceOpener> openers;
    for (const char* side : {"left", "right"}) {
      const std::string path = dir + "/" + codec.name + "_" + side + ".avi";
      openers.push_back([side, path] { return camera::open_video_source(side, path, camera::DeviceRequest{}); });
    }
    camera::CameraDriver driver(
        options, std::move(openers), [] { return int64_t{0}; }, [](const std::string&) {});
    std::vector<double> ms;
    while (!driver.finished()) {
      const std::clock_t c0 = std::clock();
      const std::size_t out = driver.step().size();
      if (out > 0) ms.push_back(1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
    }
    const eval::TimingStats t = eval::timing_stats(ms);
    std::printf("%-6s %6zu | %7.2f %7.2f %7.2f %7.2f\n", codec.name, ms.size(), t.mean_ms, t.median_ms, t.p95_ms,
                t.max_ms);
  }
  std::filesystem::remove_all(dir);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-camera", argc, argv, run); }

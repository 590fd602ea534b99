// vimot-bench-checkpoint: cost of the target filter's checkpoint
// (common/estimator/checkpoint.h, common/target/target_checkpoint.h), which
// the process writes after every update: per frame of a simulated run, the
// size of the file and the wall time of building it (checkpoint_of) and of
// writing it (serialise, hash, write, rename); for comparison the bare
// write + rename of a buffer of the size before the whole state was kept
// (205 152 bytes: the IMU and 50 SLAM landmarks). One thread; prints the
// machine. Wall times: on a shared machine they depend on the load.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/checkpoint.h"
#include "common/eval/machine.h"
#include "common/process/arg_parser.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"
#include "procs/target_filter/target_filter_node.h"

namespace {

using namespace vimot;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

struct Stats {
  std::vector<double> ms;
  void print(const char* what) {
    if (ms.empty()) return;
    std::sort(ms.begin(), ms.end());
    double sum = 0.0;
    for (double x : ms) sum += x;
    std::printf("%-34s mean %6.3f ms  p50 %6.3f  p99 %6.3f  max %6.3f  (%zu)\n", what, sum / ms.size(),
                ms[ms.size() / 2], ms[std::min(ms.size() - 1, ms.size() * 99 / 100)], ms.back(), ms.size());
  }
};

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-checkpoint",
                 "Size and wall time per frame of the target filter's checkpoint (build, write) on a\n"
                 "simulated run, and the bare write + rename of the former 205 152-byte checkpoint.");
  args.add_option("sim-config", "FILE", "scenario", "config/sim_paper.yaml");
  args.add_option("config", "FILE", "target filter config", "config/target_filter.yaml");
  args.add_option("duration", "SECONDS", "simulated time", "30");
  args.add_option("seed", "N", "simulator seed", "1");
  args.add_option("dir", "DIR", "where the checkpoint is written (the processes use /dev/shm)", "/dev/shm");
  if (!args.parse(argc, argv)) return 0;

  sim::SimConfig cfg = sim::from_config(Config::load_file(args.get("sim-config")));
  cfg.duration = args.get_double("duration");
  cfg.seed = static_cast<uint64_t>(args.get_int("seed"));
  cfg.ground_truth_events = true;
  const std::string path = args.get("dir") + "/vimot-bench-checkpoint-" + std::to_string(::getpid()) + ".ckpt";

  TargetFilterNode node(node_options_from_config(Config::load_file(args.get("config"))), {});
  Stats build, write, bare;
  std::vector<std::size_t> sizes;
  int64_t last_frames = 0;
  std::string why;
  const std::string old_size(205152, 'x');
  auto after_input = [&] {
    if (node.frames_processed() == last_frames || !node.initialized()) return;
    last_frames = node.frames_processed();
    Clock::time_point t0 = Clock::now();
    const estimator::EstimatorCheckpoint c = estimator::checkpoint_of(node.estimator(), node.checkpoint_extension());
    build.ms.push_back(ms_since(t0));
    std::size_t bytes = 0;
    t0 = Clock::now();
    if (!estimator::write_checkpoint(path, c, &why, &bytes)) throw std::runtime_error(why);
    write.ms.push_back(ms_since(t0));
    sizes.push_back(bytes);
    t0 = Clock::now();
    {
      std::ofstream out(path + ".old.tmp", std::ios::binary | std::ios::trunc);
      out.write(old_size.data(), static_cast<std::streamsize>(old_size.size()));
    }
    std::rename((path + ".old.tmp").c_str(), (path + ".old").c_str());
    bare.ms.push_back(ms_since(t0));
  };
  sim::Simulator s(cfg);
  s.run([&](const sim::SimEvent& e) {
    if (const auto* imu = std::get_if<ImuData>(&e)) node.on_imu(*imu);
    if (const auto* frame = std::get_if<CameraFrame>(&e)) node.on_frame(*frame);
    if (const auto* gt = std::get_if<GroundTruth>(&e)) node.on_ground_truth(*gt);
    after_input();
  });
  std::remove(path.c_str());
  std::remove((path + ".old").c_str());

  const eval::MachineInfo machine = eval::machine_info();
  std::sort(sizes.begin(), sizes.end());
  std::printf("vimot-bench-checkpoint: %s, %s, %.0f s, seed %lld, written to %s\nmachine: %d CPUs, %s\n\n",
              args.get("sim-config").c_str(), args.get("config").c_str(), cfg.duration,
              static_cast<long long>(cfg.seed), args.get("dir").c_str(), machine.nproc, machine.cpu_model.c_str());
  if (sizes.empty()) throw std::runtime_error("no frame was processed");
  std::printf("checkpoint size: median %zu bytes, max %zu (target %s at the end)\n", sizes[sizes.size() / 2],
              sizes.back(), node.target_initialized() ? "initialised" : "not initialised");
  build.print("checkpoint_of (build)");
  write.print("write_checkpoint (write + rename)");
  bare.print("bare write of 205 152 bytes");
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-checkpoint", argc, argv, run); }

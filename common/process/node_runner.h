#pragma once
// The LCM side shared by the process nodes: how a node's events reach the
// heartbeat counters (every node), and the subscribe → run loop with the
// bounded IMU wait of the estimator nodes, which have on_imu, on_frame,
// on_ground_truth and flush (VinsNode, TargetFilterNode).

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "common/process/lcm_conversions.h"
#include "common/process/node_event.h"
#include "common/process/process.h"
#include "vimot/features_t.hpp"
#include "vimot/ground_truth_t.hpp"
#include "vimot/imu_t.hpp"

namespace vimot {

/// Info is logged; dropped input and errors are counted in the heartbeat,
/// and input handled from the catch-up log as "caught up <stream>".
inline std::function<void(const NodeEvent&)> report_events_to(Process& process) {
  auto caught_up = std::make_shared<std::map<std::string, int64_t>>();
  return [&process, caught_up](const NodeEvent& e) {
    switch (e.kind) {
      case NodeEvent::Kind::kInfo: log_info(e.message); break;
      case NodeEvent::Kind::kDropped: process.report_dropped(e.message); break;
      case NodeEvent::Kind::kError: process.report_error(e.message); break;
      case NodeEvent::Kind::kLost: process.report_lost(e.count, e.message, e.stream); break;
      case NodeEvent::Kind::kCaughtUp:
        process.set_counter("caught up " + e.stream, (*caught_up)[e.stream] += e.count);
        break;
    }
  };
}

/// --catch-up-log FILE (with --checkpoint): a respawned estimator handles the
/// input it missed from the run's LCM log before the live input.
inline void add_catch_up_option(ArgParser& args) {
  args.add_option("catch-up-log", "FILE",
                  "with --checkpoint: after a restore, first handle the input missed while down from this LCM log\n"
                  "(vimot-logger's), so the estimate goes on as if never stopped; bridged where the log lacks it");
}

/// The catch-up log and the input channels (the process's channel names) for `options`.
template <typename NodeOptions>
void set_catch_up(Process& process, NodeOptions* options, bool use_ground_truth) {
  if (!process.args().given("catch-up-log")) return;
  if (!process.args().given("checkpoint")) {
    throw ArgError(process.name() + ": --catch-up-log needs --checkpoint (it goes on from the restored state)");
  }
  options->catch_up_log = process.args().get("catch-up-log");
  options->catch_up_channels.imu = process.channel("imu", "IMU");
  options->catch_up_channels.features = process.channel("features", "FEATURES");
  options->catch_up_channels.ground_truth = use_ground_truth ? process.channel("ground_truth", "GROUND_TRUTH") : "";
}

/// Subscribes IMU, FEATURES and (if `use_ground_truth`) GROUND_TRUTH to the
/// node and handles LCM until stopped. If the IMU stream stops for
/// `max_wait_s` of wall time, queued frames are processed with the data
/// there is rather than held forever. Only a quiet network counts as a
/// stop: after a frame update that took long on a loaded CPU, the IMU
/// samples waiting in the socket come first (else the next frame would be
/// processed without them, unlike offline). Returns the exit status.
template <typename Node>
int run_estimator_node(Process& process, Node& node, bool use_ground_truth, double max_wait_s) {
  using Clock = std::chrono::steady_clock;
  Clock::time_point last_imu_wall = Clock::now();
  // 120 s of input at the simulator's 200 Hz IMU and ground truth, 10 Hz
  // frames (≈ 40 MB at most) wait while the process is behind on a loaded
  // CPU (LCM's default queue, 30 messages, is 0.15 s of IMU): the demo's
  // whole run, so what a process that fell behind still holds at the stop
  // is drained or counted (Process, --drain). A queue that overflows loses
  // messages silently; the stream's next message, handled or left at the
  // stop, shows the gap, but not after its last one.
  constexpr int kImuQueue = 24000, kFeaturesQueue = 1200;
  using Input = EstimatorInput;
  process.subscribe<imu_t>(
      process.channel("imu", "IMU"),
      [&](const imu_t& m) {
        node.on_imu(from_lcm(m));
        last_imu_wall = Clock::now();  // after the frames this sample released were processed
      },
      kImuQueue, [&](const imu_t& m) { node.count_left(Input::kImu, m.utime); });
  process.subscribe<features_t>(
      process.channel("features", "FEATURES"), [&](const features_t& m) { node.on_frame(from_lcm(m)); },
      kFeaturesQueue, [&](const features_t& m) { node.count_left(Input::kFrame, m.utime); });
  if (use_ground_truth) {
    process.subscribe<ground_truth_t>(
        process.channel("ground_truth", "GROUND_TRUTH"),
        [&](const ground_truth_t& m) { node.on_ground_truth(from_lcm(m)); }, kImuQueue,
        [&](const ground_truth_t& m) { node.count_left(Input::kGroundTruth, m.utime); });
  }
  log_info(use_ground_truth ? "waiting for GROUND_TRUTH to initialise" : "initialising at rest from the IMU");
  const int status = process.run([&] {
    if (process.idle_after_timeout() &&
        std::chrono::duration<double>(Clock::now() - last_imu_wall).count() > max_wait_s) {
      node.flush();
    }
  });
  node.flush();
  log_info("processed ", node.frames_processed(), " frames, ", node.resets(), " resets");
  return status;
}

}  // namespace vimot

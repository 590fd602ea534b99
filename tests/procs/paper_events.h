#pragma once
// The paper scenario's event stream for the process-logic tests.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "common/config/config.h"
#include "common/sim/simulator.h"

namespace vimot {

inline std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

/// All events of `duration` s of a simulator config (default the paper's) with noise seed 5.
inline std::vector<sim::SimEvent> simulate(double duration, const std::string& config = "config/sim_paper.yaml") {
  sim::SimConfig cfg = sim::from_config(Config::load_file(source_path(config)));
  cfg.seed = 5;
  cfg.duration = duration;
  cfg.ground_truth_events = true;
  sim::Simulator s(cfg);
  std::vector<sim::SimEvent> events;
  s.run([&](const sim::SimEvent& e) { events.push_back(e); });
  return events;
}

/// Feeds one event to a node (VinsNode, TargetFilterNode).
template <typename Node>
void feed_one(Node& node, const sim::SimEvent& e) {
  if (const auto* imu = std::get_if<ImuData>(&e)) node.on_imu(*imu);
  if (const auto* frame = std::get_if<CameraFrame>(&e)) node.on_frame(*frame);
  if (const auto* gt = std::get_if<GroundTruth>(&e)) node.on_ground_truth(*gt);
}

/// Feeds `events` to a node in order, then flushes it.
template <typename Node>
void feed(Node& node, const std::vector<sim::SimEvent>& events) {
  for (const auto& e : events) feed_one(node, e);
  node.flush();
}

/// A folder for a test's files, removed with everything in it at the end.
struct TempDir {
  std::filesystem::path path;
  TempDir() : path(std::filesystem::temp_directory_path() / ("vimot_procs_test_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

/// Every camera frame but the first moved before the last 5 IMU samples up
/// to its time, as if it arrived early on the network (the first stays after
/// the ground truth that initialises the filter).
inline std::vector<sim::SimEvent> frames_early(std::vector<sim::SimEvent> early) {
  bool first_frame = true;
  for (std::size_t i = 0; i < early.size(); ++i) {
    if (!std::holds_alternative<CameraFrame>(early[i])) continue;
    if (std::exchange(first_frame, false)) continue;
    std::size_t j = i;
    int imu_passed = 0;
    while (j > 0 && imu_passed < 5) {
      if (std::holds_alternative<ImuData>(early[j - 1])) ++imu_passed;
      if (std::holds_alternative<CameraFrame>(early[j - 1])) break;
      std::swap(early[j], early[j - 1]);
      --j;
    }
  }
  return early;
}

}  // namespace vimot

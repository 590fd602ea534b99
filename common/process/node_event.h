#pragma once
// What happened to a process node's input, for the process's heartbeat
// counters and log (common/process/node_runner.h). Nodes hold the process
// logic without LCM, so this header has none either.

#include <cstdint>
#include <string>

namespace vimot {

struct NodeEvent {
  /// kLost: `count` messages of a stream never arrived (utime gap);
  /// kError: also a reset of the estimate (the heartbeat says degraded);
  /// kCaughtUp: `count` messages of a stream a respawned node missed were
  /// handled from the run's log (--catch-up-log).
  enum class Kind { kInfo, kDropped, kError, kLost, kCaughtUp } kind{Kind::kInfo};
  std::string message;
  int64_t count{1};
  std::string stream{};  // kLost, kCaughtUp: which input stream (IMU, FEATURES, GROUND_TRUTH)
};

/// The input streams of an estimator node (run_estimator_node).
enum class EstimatorInput { kImu, kFrame, kGroundTruth };

}  // namespace vimot

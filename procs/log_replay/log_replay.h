#pragma once
// Deterministic replay of a recorded LCM run through the estimator Nodes
// (VinsNode, TargetFilterNode): the logged inputs (IMU, FEATURES,
// GROUND_TRUTH, names from each process's config) are fed in log order, in
// one thread, as fast as the CPU allows, and every output is encoded exactly
// as the live process publishes it (to_lcm) and compared byte for byte with
// the outputs the live processes logged. The Nodes order their inputs by
// utime (procs/vins/vins_node.h), so the logger's interleaving of the
// channels does not change the result: an undisturbed live run is
// reproduced bit for bit, and so is one whose process was respawned and
// caught up from the log (--catch-up-log; what it published again is
// counted as republished). Not reproducible: a run in which the live
// process lost or skipped input the logger got (counted in its heartbeats),
// was restarted without catch-up, or flushed a frame because the IMU
// stalled for its --max-wait of wall time.

#include <cstdint>
#include <string>
#include <vector>

namespace vimot {

struct ReplaySetup {
  /// A vins config (config/vins.yaml); empty: no vins.
  std::string vins_config;
  /// A target_filter config (config/target_filter.yaml); empty: none.
  std::string target_filter_config;
  /// Overrides the configs' init.perturb_seed (as the processes' --perturb-seed); < 0: keep.
  int64_t perturb_seed{-1};
  /// Write the replayed outputs, with the log's ground truth (channel of the
  /// first process's config), to this LCM log (event time = utime), which
  /// vimot-log-eval evaluates as a live run's; empty: none.
  std::string out_log;
  /// Inputs before this utime are not fed: the Nodes start as a process
  /// started at that point of the run would (e.g. a fresh start to compare
  /// a respawned process with); 0: from the beginning.
  int64_t from_utime{0};
};

/// One output channel: the live run's messages against the replay's, in order
/// (with from_utime: only the recorded messages at or after it).
struct ChannelComparison {
  std::string channel;
  int64_t recorded{0};
  int64_t replayed{0};
  /// Recorded messages equal byte for byte to the replayed one in order.
  int64_t identical{0};
  /// Replayed messages the log lacks between (or after) identical ones: the
  /// live process published them, the logger did not get them (UDP).
  int64_t not_logged{0};
  /// Recorded messages equal byte for byte to a replayed one already
  /// matched: published again by a process respawned from its checkpoint
  /// (it had published them after the checkpoint before it died).
  int64_t republished{0};
  /// Index of the first recorded message not reproduced, -1 if every one was.
  int64_t first_difference{-1};
  /// utime of the recorded message there (-1 if the recording ended first).
  int64_t first_difference_utime{-1};

  bool equal() const { return first_difference < 0; }
};

struct ReplayReport {
  int64_t events{0};      // log events read
  int64_t inputs{0};      // input messages fed to a Node
  int64_t malformed{0};   // inputs that did not decode or convert (skipped, as the live process does)
  int64_t node_errors{0};   // errors the Nodes reported
  int64_t node_dropped{0};  // input the Nodes dropped or counted as lost
  double data_span_s{0.0};  // IMU utime span of the log
  double cpu_s{0.0};        // CPU time of the replay (this thread)
  std::vector<ChannelComparison> channels;

  /// Every output channel equal and at least one output compared.
  bool identical() const;
};

/// Replays `log_path` (throws std::runtime_error if it cannot be read,
/// ConfigError on a bad config, std::invalid_argument if no process is set).
ReplayReport replay_log(const std::string& log_path, const ReplaySetup& setup);

}  // namespace vimot

#pragma once
// vimot-deputy's protocol logic without LCM: turns a sheriff's orders into
// the desired state of each command, runs the commands through the
// sheriff's ProcessRunner (process groups, stop signal then SIGKILL,
// respawn with back-off) and assembles the deputy info.

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "procs/deputy/proc_stats.h"
#include "procs/sheriff/process_runner.h"
#include "procs/sheriff/procman_protocol.h"

namespace vimot::deputy {

struct DeputyOptions {
  /// The name sheriffs address this deputy by (orders2_t.host).
  std::string host;
  /// Orders older than this are ignored (a sheriff with a wrong clock, or
  /// replayed orders), as procman's deputy does.
  int64_t max_order_age_us{60'000'000};
  /// Environment, back-off and orphan handling for every command. on_output
  /// and on_event are replaced: both go to the output callback.
  sheriff::RunnerOptions runner;
};

/// Semantics (those of libbot2's bot-procman-deputy), per command, keyed by
/// the sheriff's id:
///  * force_quit: stop it (and cancel a pending respawn);
///  * desired_runid != actual_runid: stop it if it runs, then start it and
///    take desired_runid as actual_runid (a restart is a new run id);
///  * a command missing from the orders is stopped and then forgotten.
/// A changed exec, stop signal, stop time or auto_respawn applies at the
/// next start, never to a running process. Orders for another host, or
/// older than max_order_age_us, are ignored.
class DeputyNode {
 public:
  using OutputFn = std::function<void(const sheriff::DeputyOutput&)>;

  /// Throws std::invalid_argument for an empty host.
  DeputyNode(DeputyOptions options, OutputFn on_output);
  ~DeputyNode();

  /// Returns true when the orders were for this deputy and changed
  /// something (then the caller publishes info at once).
  bool OnOrders(const sheriff::DeputyOrders& orders, int64_t now_utime);

  /// Runs the commands' event loops for up to `max_wait`; returns true when
  /// a command's state changed (started, stopped, exited).
  bool Poll(std::chrono::milliseconds max_wait, int64_t now_utime);

  /// The info message: each command's actual state, CPU and memory. CPU
  /// figures are over the time since the previous call.
  sheriff::DeputyInfo Info(int64_t now_utime);

  /// Stops every command (deputy shutdown); Poll() until IsIdle().
  void StopAll();
  bool IsIdle() const;

  const std::string& host() const { return options_.host; }
  /// The sheriff whose orders were obeyed last ("" before any).
  const std::string& sheriff_name() const { return sheriff_name_; }

 private:
  struct Command {
    int32_t sheriff_id{0};
    /// From the latest orders.
    sheriff::ProcmanCommand wanted;
    int32_t desired_runid{0};
    bool force_quit{false};
    bool removed{false};
    int32_t actual_runid{0};
    /// Runs `running_spec`; rebuilt at a start when `wanted` differs.
    std::unique_ptr<sheriff::ProcessRunner> runner;
    sheriff::ProcmanCommand running_spec;
    std::optional<ProcessStats> last_stats;
    float cpu_usage{0.0f};
    sheriff::CommandStatus last_status{sheriff::CommandStatus::kStopped};
  };

  /// Moves one command towards its desired state; true if it acted.
  bool Reconcile(Command* c);
  void Say(int32_t sheriff_id, const std::string& text, int64_t now_utime) const;
  std::unique_ptr<sheriff::ProcessRunner> MakeRunner(const Command& c);

  DeputyOptions options_;
  OutputFn on_output_;
  std::map<int32_t, Command> commands_;
  std::string sheriff_name_;
  bool stopping_all_{false};
  /// Time of the current OnOrders()/Poll(), for output read inside them.
  int64_t now_utime_{0};
  std::optional<SystemStats> last_system_;
  float cpu_load_{0.0f};
};

}  // namespace vimot::deputy

#pragma once
// vimot-sheriff --lcm without LCM: the Sheriff's run (selection, script,
// --duration, signals, orderly stop) with deputies running the commands
// over procman's protocol instead of a local ProcessRunner. main.cc
// publishes DueOrders() and feeds OnInfo().

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "procs/sheriff/remote_commands.h"
#include "procs/sheriff/script_executor.h"
#include "procs/sheriff/sheriff.h"

namespace vimot::sheriff {

/// The run ends (Step() returns the exit code) as Sheriff::Run's does: a
/// script failed (1); --duration passed (0); a signal (128 + signal);
/// everything selected ended on its own (0 if all exited with code 0, else
/// 1). Before that every command is stopped; a deputy that does not confirm
/// within the longest stop_time_allowed + `stop_grace` is given up on.
class RemoteSheriff {
 public:
  /// Throws std::invalid_argument as Sheriff does, and for exit_when (not
  /// supported over the protocol).
  RemoteSheriff(SheriffConfig config, SheriffOptions options, RemoteOptions remote,
                std::chrono::milliseconds stop_grace = std::chrono::milliseconds(5000));

  /// Starts the selection (or the script).
  void Begin();
  /// A deputy's info; reports state changes through the event sink.
  void OnInfo(const DeputyInfo& info);
  /// "[host:name] " for output of a command of ours, nullopt for others'.
  std::optional<std::string> OutputPrefix(const DeputyOutput& output) const;
  /// Advances the run; `signal` is one received since the last call, or 0.
  /// Returns the exit code once the run is over.
  std::optional<int> Step(int signal);
  /// The orders to publish now: every host's, when they changed or a second
  /// passed (procman re-sends orders so a restarted deputy catches up).
  std::vector<DeputyOrders> DueOrders(int64_t now_utime);

  const RemoteCommands& commands() const { return commands_; }

 private:
  using Clock = std::chrono::steady_clock;
  void BeginShutdown(int exit_code, const std::string& why);
  int IdleExitCode() const;
  void Emit(const std::string& message) const;

  SheriffConfig config_;
  SheriffOptions options_;
  RemoteCommands commands_;
  std::chrono::milliseconds stop_grace_;
  std::vector<std::string> selected_;
  std::optional<ScriptExecutor> script_;
  Clock::time_point end_{Clock::time_point::max()};
  Clock::time_point give_up_at_{Clock::time_point::max()};
  Clock::time_point next_orders_{};
  bool shutting_down_{false};
  int exit_code_{0};
  /// Status and pid last reported per command, in config order.
  std::vector<std::pair<CommandStatus, pid_t>> last_status_;
};

}  // namespace vimot::sheriff

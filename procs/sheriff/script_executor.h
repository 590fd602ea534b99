#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "procs/sheriff/command_control.h"
#include "procs/sheriff/process_runner.h"
#include "procs/sheriff/sheriff_config.h"

namespace vimot::sheriff {

/// Runs one procman script against a ProcessRunner (or RemoteCommands), one action after the
/// other, without blocking: Step() performs every action it can and returns
/// when the script has to wait (`wait ms`, `wait ... status`, or an action's
/// `wait "running"|"stopped"`), so the caller's loop keeps forwarding output
/// and reaping processes meanwhile.
///
/// Wait semantics, per command of the target (commands of other hosts are
/// never started here and are left out):
///  * "running": the command is running. Waiting fails (the script ends with
///    an error) if it is stopped, exited or failed, since nothing in a
///    sequential script could start it any more; a pending respawn or restart
///    is waited for.
///  * "stopped": no process is alive and no respawn is pending.
/// A group target means the group and all its subgroups.
class ScriptExecutor {
 public:
  /// `config` and `runner` must outlive the executor; the runner must hold
  /// the config's commands. Throws std::invalid_argument for an unknown
  /// script. `on_event` receives progress lines (default: stderr).
  ScriptExecutor(const SheriffConfig& config, CommandControl* runner,
                 const std::string& script_name,
                 std::function<void(const std::string&)> on_event = {});

  /// Performs actions until one has to wait or the script ends. Call it
  /// after every ProcessRunner::Poll().
  void Step();

  /// True once the script has finished or failed.
  bool done() const { return done_; }
  bool failed() const { return !error_.empty(); }
  /// Why the script failed; empty if it did not.
  const std::string& error() const { return error_; }

  /// Every command the script (including scripts it runs) starts or
  /// restarts, in config order. Throws std::invalid_argument for an unknown
  /// script.
  static std::vector<std::string> CommandsStartedBy(const SheriffConfig& config,
                                                    const std::string& script_name);

 private:
  using Clock = std::chrono::steady_clock;

  struct Frame {
    const ScriptSpec* script{nullptr};
    std::size_t next_action{0};
  };

  struct Wait {
    /// Set for `wait ms`.
    std::optional<Clock::time_point> until;
    std::vector<std::string> commands;
    WaitStatus status{WaitStatus::kNone};
    const ScriptAction* action{nullptr};
  };

  std::vector<std::string> Targets(const ScriptAction& action) const;
  void Execute(const ScriptAction& action);
  /// True when the pending wait is over; sets error_ if it cannot end.
  bool WaitIsOver();
  void Fail(const std::string& message);

  const SheriffConfig& config_;
  CommandControl* runner_{nullptr};
  std::string script_name_;
  std::function<void(const std::string&)> on_event_;
  std::vector<Frame> stack_;
  std::optional<Wait> wait_;
  bool done_{false};
  std::string error_;
};

}  // namespace vimot::sheriff

#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "procs/sheriff/process_runner.h"
#include "procs/sheriff/script_executor.h"
#include "procs/sheriff/sheriff_config.h"

namespace vimot::sheriff {

/// What a headless sheriff run does (the vimot-sheriff command line).
struct SheriffOptions {
  /// Run this script. Empty: start `group`, or every command.
  std::string script;
  /// Start only the commands of this group (and its subgroups).
  std::string group;
  /// When this command ends for good (it exits and is not respawned, or it
  /// exits with code 0), stop everything else and return its exit code.
  std::string exit_when;
  /// Stop everything after this long.
  std::optional<std::chrono::milliseconds> duration;
  RunnerOptions runner;
};

/// The commands `options` starts (all, the group's, or the script's), in
/// config order. Throws std::invalid_argument for an unknown script or
/// group, or both given.
std::vector<std::string> SelectCommands(const SheriffConfig& config,
                                        const SheriffOptions& options);

/// A headless procman sheriff for this machine: owns the config, a
/// ProcessRunner for its commands and, with a script, a ScriptExecutor, and
/// runs the event loop until the run is over.
///
/// The run ends, and Run() returns, when
///  * `exit_when` ended for good: its exit status (128 + signal if killed);
///  * `duration` passed: 0;
///  * a signal arrived: 128 + signal;
///  * a script failed: 1;
///  * nothing is left to run (all commands ended, script done): 0 if every
///    command that ran exited with code 0, else 1.
/// Before returning, everything still running is stopped in reverse start
/// order (ProcessRunner::StopAll).
class Sheriff {
 public:
  /// Checks `options` against `config` and throws std::invalid_argument
  /// saying what does not fit (unknown script/group/command, both script and
  /// group, an exit_when command that the selection never starts or that
  /// belongs to another host, a non-positive duration), and
  /// std::runtime_error for an exec that uses an undefined environment
  /// variable, before anything is started.
  Sheriff(SheriffConfig config, SheriffOptions options);

  /// Runs to the end (see the class comment) and returns the exit code.
  /// `take_signal` is called once per loop iteration and returns a signal
  /// number received since the previous call, or 0: the first one stops
  /// everything in order, a further one SIGKILLs what is left.
  int Run(const std::function<int()>& take_signal = {});

  const SheriffConfig& config() const { return config_; }
  const ProcessRunner& runner() const { return runner_; }
  /// The commands the selection starts (all, the group's, or the script's).
  const std::vector<std::string>& selected_commands() const { return selected_; }

 private:
  void BeginShutdown(int exit_code, const std::string& why);
  void CheckExitWhen();
  int IdleExitCode() const;
  void Emit(const std::string& message) const;

  SheriffConfig config_;
  SheriffOptions options_;
  ProcessRunner runner_;
  std::optional<ScriptExecutor> script_;
  std::vector<std::string> selected_;
  bool shutting_down_{false};
  int exit_code_{0};
  /// exit_count of exit_when already looked at.
  int exit_when_seen_{0};
};

}  // namespace vimot::sheriff

#include "procs/sheriff/sheriff.h"

#include <string.h>

#include <algorithm>
#include <iostream>
#include <stdexcept>

namespace vimot::sheriff {

namespace {

// Upper bound on one loop iteration; the runner returns earlier when output
// or a timer is due. Also the accuracy of `wait ms` and of --duration.
constexpr std::chrono::milliseconds kLoopInterval{50};

// The sheriff's own messages go to the same sink as the runner's, so it
// needs the default sink in hand rather than leaving it to the runner.
SheriffOptions WithDefaultEventSink(SheriffOptions options) {
  if (!options.runner.on_event) {
    options.runner.on_event = [](const std::string& message) {
      std::cerr << "[sheriff] " << message << std::endl;
    };
  }
  return options;
}

}  // namespace

std::vector<std::string> SelectCommands(const SheriffConfig& config,
                                        const SheriffOptions& options) {
  std::vector<std::string> selected;
  if (!options.script.empty() && !options.group.empty()) {
    throw std::invalid_argument(
        "give either a script (" + options.script + ") or a group (" +
        options.group + ") to start, not both");
  }
  if (!options.script.empty()) {
    if (config.FindScript(options.script) == nullptr) {
      std::string known;
      for (const ScriptSpec& s : config.scripts()) known += " '" + s.name + "'";
      throw std::invalid_argument("unknown script '" + options.script +
                                  "'; the config has:" +
                                  (known.empty() ? " no scripts" : known));
    }
    selected = ScriptExecutor::CommandsStartedBy(config, options.script);
  } else if (!options.group.empty()) {
    if (config.FindGroup(options.group) == nullptr) {
      std::string known;
      for (const GroupSpec& g : config.groups()) known += " '" + g.name + "'";
      throw std::invalid_argument("unknown group '" + options.group +
                                  "'; the config has:" +
                                  (known.empty() ? " no groups" : known));
    }
    selected = config.CommandsInGroup(options.group);
  } else {
    for (const CommandSpec& c : config.commands()) selected.push_back(c.name);
  }
  return selected;
}

Sheriff::Sheriff(SheriffConfig config, SheriffOptions options)
    : config_(std::move(config)),
      options_(WithDefaultEventSink(std::move(options))),
      runner_(config_.commands(), options_.runner) {
  selected_ = SelectCommands(config_, options_);
  if (!options_.exit_when.empty()) {
    if (config_.FindCommand(options_.exit_when) == nullptr) {
      throw std::invalid_argument("--exit-when: unknown command '" +
                                  options_.exit_when + "'");
    }
    if (std::find(selected_.begin(), selected_.end(), options_.exit_when) ==
        selected_.end()) {
      throw std::invalid_argument(
          "--exit-when: command '" + options_.exit_when +
          "' is never started by " +
          (!options_.script.empty() ? "script '" + options_.script + "'"
                                    : "group '" + options_.group + "'") +
          ", so the run could never end through it");
    }
    if (!runner_.IsLocal(options_.exit_when)) {
      throw std::invalid_argument("--exit-when: command '" + options_.exit_when +
                                  "' runs on host '" +
                                  runner_.spec(options_.exit_when).host +
                                  "', which this sheriff does not start");
    }
  }
  if (options_.duration && *options_.duration <= std::chrono::milliseconds(0)) {
    throw std::invalid_argument("duration must be positive, got " +
                                std::to_string(options_.duration->count()) +
                                " ms");
  }
  // Undefined variables are configuration errors: report them now rather
  // than after half of the system has been started.
  for (const std::string& name : selected_) {
    if (runner_.IsLocal(name)) runner_.ExpandedExec(name);
  }
}

void Sheriff::Emit(const std::string& message) const {
  options_.runner.on_event(message);
}

void Sheriff::BeginShutdown(int exit_code, const std::string& why) {
  shutting_down_ = true;
  exit_code_ = exit_code;
  Emit(why + "; stopping everything");
  runner_.StopAll();
}

void Sheriff::CheckExitWhen() {
  if (options_.exit_when.empty()) return;
  const CommandState& state = runner_.state(options_.exit_when);
  if (state.status == CommandStatus::kFailed) {
    BeginShutdown(1, "'" + options_.exit_when + "' could not be started");
    return;
  }
  if (state.exit_count <= exit_when_seen_ || !state.last_exit) return;
  // Still stopping what the main process left in its group: look again
  // once the command has exited, been stopped or is due to respawn.
  if (state.status == CommandStatus::kStopping) return;
  exit_when_seen_ = state.exit_count;
  const ExitInfo exit = *state.last_exit;
  const bool clean = exit.signal == 0 && exit.exit_code == 0;
  switch (state.status) {
    case CommandStatus::kExited:
    case CommandStatus::kStopped:
      break;
    case CommandStatus::kRespawnPending:
      // A clean exit means "done", even for an auto_respawn command.
      if (!clean) return;
      runner_.Stop(options_.exit_when);
      break;
    default:
      return;  // Restarted by a script; not the end.
  }
  BeginShutdown(exit.ShellStyleCode(), "'" + options_.exit_when +
                                           "' ended with " + exit.ToString() +
                                           " (--exit-when)");
}

int Sheriff::IdleExitCode() const {
  for (const std::string& name : runner_.command_names()) {
    const CommandState& state = runner_.state(name);
    if (state.status == CommandStatus::kFailed) return 1;
    if (state.status == CommandStatus::kExited && state.last_exit &&
        state.last_exit->ShellStyleCode() != 0) {
      return 1;
    }
  }
  return 0;
}

int Sheriff::Run(const std::function<int()>& take_signal) {
  using Clock = std::chrono::steady_clock;
  for (const ConfigWarning& w : config_.warnings()) Emit(w.ToString());
  const Clock::time_point end =
      options_.duration ? Clock::now() + *options_.duration : Clock::time_point::max();

  if (!options_.script.empty()) {
    script_.emplace(config_, &runner_, options_.script, options_.runner.on_event);
  } else {
    for (const std::string& name : selected_) runner_.Start(name);
  }

  while (true) {
    if (const int signal = take_signal ? take_signal() : 0; signal != 0) {
      const std::string name = "signal " + std::to_string(signal) + " (" +
                               ::strsignal(signal) + ")";
      if (!shutting_down_) {
        BeginShutdown(128 + signal,
                      "received " + name + "; a second one kills everything");
      } else {
        Emit("received " + name + " while stopping; killing everything");
        runner_.KillAll();
      }
    }
    if (script_ && !script_->done() && !shutting_down_) {
      script_->Step();
      if (script_->failed()) BeginShutdown(1, script_->error());
    }
    runner_.Poll(kLoopInterval);
    if (!shutting_down_) CheckExitWhen();
    if (!shutting_down_ && Clock::now() >= end) {
      BeginShutdown(0, "duration reached");
    }
    if (runner_.IsIdle()) {
      if (shutting_down_) return exit_code_;
      if (!script_ || script_->done()) {
        const int code = IdleExitCode();
        Emit("nothing left running; exiting with " + std::to_string(code));
        return code;
      }
    }
  }
}

}  // namespace vimot::sheriff

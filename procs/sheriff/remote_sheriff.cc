#include "procs/sheriff/remote_sheriff.h"

#include <string.h>

#include <algorithm>
#include <iostream>
#include <stdexcept>

namespace vimot::sheriff {

RemoteSheriff::RemoteSheriff(SheriffConfig config, SheriffOptions options,
                             RemoteOptions remote, std::chrono::milliseconds stop_grace)
    : config_(std::move(config)),
      options_(std::move(options)),
      commands_(config_, std::move(remote)),
      stop_grace_(stop_grace) {
  selected_ = SelectCommands(config_, options_);
  if (!options_.exit_when.empty()) {
    throw std::invalid_argument("--exit-when is not supported with --lcm");
  }
  if (options_.duration && *options_.duration <= std::chrono::milliseconds(0)) {
    throw std::invalid_argument("duration must be positive");
  }
  if (!options_.runner.on_event) {
    options_.runner.on_event = [](const std::string& message) {
      std::cerr << "[sheriff] " << message << std::endl;
    };
  }
  for (const std::string& name : commands_.command_names()) {
    last_status_.emplace_back(commands_.state(name).status, commands_.state(name).pid);
  }
}

void RemoteSheriff::Emit(const std::string& message) const {
  options_.runner.on_event(message);
}

void RemoteSheriff::Begin() {
  for (const ConfigWarning& w : config_.warnings()) Emit(w.ToString());
  if (options_.duration) end_ = Clock::now() + *options_.duration;
  if (!options_.script.empty()) {
    script_.emplace(config_, &commands_, options_.script, options_.runner.on_event);
  } else {
    for (const std::string& name : selected_) commands_.Start(name);
  }
}

void RemoteSheriff::OnInfo(const DeputyInfo& info) {
  if (!commands_.OnInfo(info)) return;
  const std::vector<std::string> names = commands_.command_names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const CommandState& state = commands_.state(names[i]);
    if (state.status == last_status_[i].first && state.pid == last_status_[i].second) {
      continue;
    }
    last_status_[i] = {state.status, state.pid};
    std::string line = commands_.HostOf(names[i]) + ":" + names[i] + " " +
                       ToString(state.status);
    if (state.pid > 0) line += " (pid " + std::to_string(state.pid) + ")";
    if (state.status == CommandStatus::kExited && state.last_exit) {
      line += " with " + state.last_exit->ToString();
    }
    Emit(line);
  }
}

std::optional<std::string> RemoteSheriff::OutputPrefix(const DeputyOutput& output) const {
  if (const auto name = commands_.NameOf(output.deputy_name, output.sheriff_id)) {
    return "[" + output.deputy_name + ":" + *name + "] ";
  }
  if (output.sheriff_id == 0) return "[" + output.deputy_name + "] ";
  return std::nullopt;
}

void RemoteSheriff::BeginShutdown(int exit_code, const std::string& why) {
  shutting_down_ = true;
  exit_code_ = exit_code;
  Emit(why + "; stopping everything");
  commands_.StopAll();
  std::chrono::milliseconds longest{0};
  for (const CommandSpec& c : config_.commands()) {
    longest = std::max(longest, c.stop_time_allowed);
  }
  give_up_at_ = Clock::now() + longest + stop_grace_;
}

int RemoteSheriff::IdleExitCode() const {
  for (const std::string& name : selected_) {
    const CommandState& state = commands_.state(name);
    if (state.status == CommandStatus::kExited && state.last_exit &&
        state.last_exit->ShellStyleCode() != 0) {
      return 1;
    }
  }
  return 0;
}

std::optional<int> RemoteSheriff::Step(int signal) {
  if (signal != 0) {
    const std::string name =
        "signal " + std::to_string(signal) + " (" + ::strsignal(signal) + ")";
    if (!shutting_down_) {
      BeginShutdown(128 + signal, "received " + name);
    } else {
      Emit("received " + name + " while stopping; leaving the deputies to it");
      return exit_code_;
    }
  }
  if (script_ && !script_->done() && !shutting_down_) {
    script_->Step();
    if (script_->failed()) BeginShutdown(1, script_->error());
  }
  if (!shutting_down_ && Clock::now() >= end_) BeginShutdown(0, "duration reached");
  if (shutting_down_) {
    if (commands_.AllStopped()) return exit_code_;
    if (Clock::now() >= give_up_at_) {
      Emit("deputies did not confirm the stop; exiting anyway");
      return exit_code_ != 0 ? exit_code_ : 1;
    }
    return std::nullopt;
  }
  if (commands_.AllStopped() && (!script_ || script_->done())) {
    const int code = IdleExitCode();
    Emit("nothing left running; exiting with " + std::to_string(code));
    return code;
  }
  return std::nullopt;
}

std::vector<DeputyOrders> RemoteSheriff::DueOrders(int64_t now_utime) {
  const Clock::time_point now = Clock::now();
  if (!commands_.TakeOrdersChanged() && now < next_orders_) return {};
  next_orders_ = now + std::chrono::seconds(1);
  return commands_.Orders(now_utime);
}

}  // namespace vimot::sheriff

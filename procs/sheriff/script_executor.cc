#include "procs/sheriff/script_executor.h"

#include <algorithm>
#include <iostream>
#include <stdexcept>

namespace vimot::sheriff {

namespace {

bool IsStoppedStatus(CommandStatus status) {
  return status == CommandStatus::kStopped || status == CommandStatus::kExited ||
         status == CommandStatus::kFailed || status == CommandStatus::kRemote;
}

}  // namespace

ScriptExecutor::ScriptExecutor(const SheriffConfig& config, CommandControl* runner,
                               const std::string& script_name,
                               std::function<void(const std::string&)> on_event)
    : config_(config),
      runner_(runner),
      script_name_(script_name),
      on_event_(std::move(on_event)) {
  if (runner_ == nullptr) {
    throw std::invalid_argument("ScriptExecutor: runner is null");
  }
  const ScriptSpec* script = config_.FindScript(script_name);
  if (script == nullptr) {
    throw std::invalid_argument("unknown script '" + script_name + "'");
  }
  if (!on_event_) {
    on_event_ = [](const std::string& message) {
      std::cerr << "[sheriff] " << message << std::endl;
    };
  }
  stack_.push_back({script, 0});
}

std::vector<std::string> ScriptExecutor::CommandsStartedBy(
    const SheriffConfig& config, const std::string& script_name) {
  std::set<std::string> started;
  std::set<std::string> visited;
  std::vector<std::string> todo = {script_name};
  while (!todo.empty()) {
    const std::string name = todo.back();
    todo.pop_back();
    if (!visited.insert(name).second) continue;
    const ScriptSpec* script = config.FindScript(name);
    if (script == nullptr) {
      throw std::invalid_argument("unknown script '" + name + "'");
    }
    for (const ScriptAction& a : script->actions) {
      if (a.kind == ActionKind::kRunScript) todo.push_back(a.name);
      if (a.kind != ActionKind::kStart && a.kind != ActionKind::kRestart) continue;
      if (a.target == ActionTarget::kCommand) started.insert(a.name);
      if (a.target == ActionTarget::kGroup) {
        for (const std::string& c : config.CommandsInGroup(a.name)) started.insert(c);
      }
      if (a.target == ActionTarget::kEverything) {
        for (const CommandSpec& c : config.commands()) started.insert(c.name);
      }
    }
  }
  std::vector<std::string> ordered;
  for (const CommandSpec& c : config.commands()) {
    if (started.count(c.name) > 0) ordered.push_back(c.name);
  }
  return ordered;
}

std::vector<std::string> ScriptExecutor::Targets(const ScriptAction& action) const {
  switch (action.target) {
    case ActionTarget::kCommand:
      return {action.name};
    case ActionTarget::kGroup:
      return config_.CommandsInGroup(action.name);
    case ActionTarget::kEverything: {
      std::vector<std::string> all;
      for (const CommandSpec& c : config_.commands()) all.push_back(c.name);
      return all;
    }
    default:
      break;
  }
  return {};
}

void ScriptExecutor::Fail(const std::string& message) {
  error_ = "script '" + script_name_ + "': " + message;
  done_ = true;
  wait_.reset();
  stack_.clear();
}

void ScriptExecutor::Execute(const ScriptAction& action) {
  on_event_("script '" + script_name_ + "': " + action.ToString());
  switch (action.kind) {
    case ActionKind::kStart:
    case ActionKind::kStop:
    case ActionKind::kRestart: {
      const std::vector<std::string> targets = Targets(action);
      for (const std::string& name : targets) {
        if (action.kind == ActionKind::kStart) runner_->Start(name);
        if (action.kind == ActionKind::kStop) runner_->Stop(name);
        if (action.kind == ActionKind::kRestart) runner_->Restart(name);
      }
      if (action.wait != WaitStatus::kNone) {
        wait_ = Wait{std::nullopt, targets, action.wait, &action};
      }
      return;
    }
    case ActionKind::kWaitMs:
      wait_ = Wait{Clock::now() + action.delay, {}, WaitStatus::kNone, &action};
      return;
    case ActionKind::kWaitStatus:
      wait_ = Wait{std::nullopt, Targets(action), action.wait, &action};
      return;
    case ActionKind::kRunScript: {
      // Cycles were rejected by the parser, so the stack stays bounded.
      const ScriptSpec* script = config_.FindScript(action.name);
      if (script == nullptr) {
        Fail("unknown script '" + action.name + "'");
        return;
      }
      stack_.push_back({script, 0});
      return;
    }
  }
}

bool ScriptExecutor::WaitIsOver() {
  if (wait_->until) return Clock::now() >= *wait_->until;
  for (const std::string& name : wait_->commands) {
    if (!runner_->IsLocal(name)) continue;
    const CommandState& state = runner_->state(name);
    if (wait_->status == WaitStatus::kStopped) {
      if (!IsStoppedStatus(state.status)) return false;
      continue;
    }
    if (state.status == CommandStatus::kRunning) continue;
    if (IsStoppedStatus(state.status)) {
      std::string detail = ToString(state.status);
      if (state.status == CommandStatus::kExited && state.last_exit) {
        detail += " with " + state.last_exit->ToString();
      }
      if (state.status == CommandStatus::kFailed) detail += ": " + state.failure;
      Fail("cmd '" + name + "' will not run again (" + detail + "), but `" +
           wait_->action->ToString() + "` (" +
           wait_->action->location.ToString() + ") waits for it to be running");
      return false;
    }
    return false;  // Stopping for a restart, or respawn pending.
  }
  return true;
}

void ScriptExecutor::Step() {
  while (!done_) {
    if (wait_) {
      if (!WaitIsOver()) return;
      wait_.reset();
    }
    if (stack_.empty()) {
      done_ = true;
      on_event_("script '" + script_name_ + "' finished");
      return;
    }
    Frame& frame = stack_.back();
    if (frame.next_action == frame.script->actions.size()) {
      stack_.pop_back();
      continue;
    }
    const ScriptAction& action = frame.script->actions[frame.next_action++];
    Execute(action);
  }
}

}  // namespace vimot::sheriff

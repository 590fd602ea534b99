#include "procs/deputy/deputy_node.h"

#include <stdexcept>
#include <utility>
#include <vector>

namespace vimot::deputy {

using sheriff::CommandStatus;

namespace {

constexpr int kCannotRunExitCode = 127;

bool IsAlive(CommandStatus s) {
  return s == CommandStatus::kRunning || s == CommandStatus::kStopping;
}

}  // namespace

DeputyNode::DeputyNode(DeputyOptions options, OutputFn on_output)
    : options_(std::move(options)), on_output_(std::move(on_output)) {
  if (options_.host.empty()) throw std::invalid_argument("deputy: empty host name");
  if (!on_output_) on_output_ = [](const sheriff::DeputyOutput&) {};
  last_system_ = ReadSystemStats();
}

DeputyNode::~DeputyNode() = default;

void DeputyNode::Say(int32_t sheriff_id, const std::string& text,
                     int64_t now_utime) const {
  on_output_({now_utime, options_.host, sheriff_id, text});
}

std::unique_ptr<sheriff::ProcessRunner> DeputyNode::MakeRunner(const Command& c) {
  sheriff::RunnerOptions runner_options = options_.runner;
  const int32_t id = c.sheriff_id;
  // The runner reports through callbacks without a clock; output is stamped
  // with the time of the Poll() that read it.
  runner_options.on_output = [this, id](const std::string&, sheriff::OutputStream,
                                        const std::string& line) {
    Say(id, line + "\n", now_utime_);
  };
  runner_options.on_event = [this, id](const std::string& message) {
    Say(id, message + "\n", now_utime_);
  };
  std::vector<sheriff::CommandSpec> specs{sheriff::ToCommandSpec(c.wanted)};
  return std::make_unique<sheriff::ProcessRunner>(std::move(specs), runner_options);
}

bool DeputyNode::OnOrders(const sheriff::DeputyOrders& orders, int64_t now_utime) {
  now_utime_ = now_utime;
  if (stopping_all_ || orders.host != options_.host) return false;
  if (now_utime - orders.utime > options_.max_order_age_us) {
    Say(0, "ignoring stale orders from '" + orders.sheriff_name + "' (" +
               std::to_string((now_utime - orders.utime) / 1'000'000) +
               " s old); check the clocks\n",
        now_utime);
    return false;
  }
  if (sheriff_name_ != orders.sheriff_name) {
    Say(0, "obeying sheriff '" + orders.sheriff_name + "'\n", now_utime);
    sheriff_name_ = orders.sheriff_name;
  }
  bool acted = false;
  for (auto& [id, c] : commands_) c.removed = true;
  for (const sheriff::CommandOrder& order : orders.cmds) {
    auto [it, added] = commands_.try_emplace(order.sheriff_id);
    Command& c = it->second;
    if (added) {
      c.sheriff_id = order.sheriff_id;
      acted = true;
    }
    if (c.wanted != order.cmd) acted = true;
    c.wanted = order.cmd;
    c.desired_runid = order.desired_runid;
    c.force_quit = order.force_quit;
    c.removed = false;
  }
  for (auto& [id, c] : commands_) acted |= Reconcile(&c);
  return acted;
}

bool DeputyNode::Reconcile(Command* c) {
  const CommandStatus status =
      c->runner ? c->runner->state(c->running_spec.name).status : CommandStatus::kStopped;
  const bool stop = c->force_quit || c->removed || stopping_all_;
  if (stop) {
    // A pending respawn is cancelled by Stop() as well.
    if (status == CommandStatus::kRunning || status == CommandStatus::kRespawnPending) {
      c->runner->Stop(c->running_spec.name);
      return true;
    }
    return false;
  }
  if (c->desired_runid == c->actual_runid) return false;
  if (status == CommandStatus::kRunning || status == CommandStatus::kRespawnPending) {
    c->runner->Stop(c->running_spec.name);
    return true;
  }
  if (status == CommandStatus::kStopping) return false;
  if (!c->runner || c->running_spec != c->wanted) {
    c->runner = MakeRunner(*c);
    c->running_spec = c->wanted;
  }
  c->actual_runid = c->desired_runid;
  c->last_stats.reset();
  c->runner->Start(c->running_spec.name);
  return true;
}

bool DeputyNode::Poll(std::chrono::milliseconds max_wait, int64_t now_utime) {
  now_utime_ = now_utime;
  bool changed = false;
  // Each command has its own runner; only the first waits, so a deputy with
  // many commands still answers orders promptly.
  std::chrono::milliseconds wait = max_wait;
  for (auto it = commands_.begin(); it != commands_.end();) {
    Command& c = it->second;
    if (c.runner) {
      c.runner->Poll(wait);
      wait = std::chrono::milliseconds(0);
      const CommandStatus status = c.runner->state(c.running_spec.name).status;
      if (status != c.last_status) {
        c.last_status = status;
        changed = true;
      }
    }
    changed |= Reconcile(&c);
    const bool idle = !c.runner || c.runner->IsIdle();
    if (c.removed && idle) {
      it = commands_.erase(it);
      changed = true;
    } else {
      ++it;
    }
  }
  return changed;
}

sheriff::DeputyInfo DeputyNode::Info(int64_t now_utime) {
  sheriff::DeputyInfo info;
  info.utime = now_utime;
  info.host = options_.host;
  const std::optional<SystemStats> system = ReadSystemStats();
  if (system && last_system_) {
    cpu_load_ = JiffyFraction(last_system_->busy_jiffies, system->busy_jiffies,
                              last_system_->total_jiffies, system->total_jiffies);
  }
  if (system) {
    info.phys_mem_total_bytes = system->mem_total_bytes;
    info.phys_mem_free_bytes = system->mem_free_bytes;
    info.swap_total_bytes = system->swap_total_bytes;
    info.swap_free_bytes = system->swap_free_bytes;
  }
  info.cpu_load = cpu_load_;
  for (auto& [id, c] : commands_) {
    sheriff::CommandReport report;
    report.cmd = c.runner ? c.running_spec : c.wanted;
    report.sheriff_id = c.sheriff_id;
    report.actual_runid = c.actual_runid;
    if (c.runner) {
      const sheriff::CommandState& state = c.runner->state(c.running_spec.name);
      if (IsAlive(state.status) && state.pid > 0) report.pid = state.pid;
      if (state.last_exit) report.exit_code = sheriff::EncodeWaitStatus(*state.last_exit);
      // Could not be started (undefined variable, fork failure; the reason
      // went out on PMD_PRINTF): the shell's "cannot run" status.
      if (state.status == CommandStatus::kFailed) {
        report.exit_code = sheriff::EncodeWaitStatus({kCannotRunExitCode, 0});
      }
    }
    if (report.pid > 0) {
      const std::optional<ProcessStats> stats = ReadProcessStats(report.pid);
      if (stats) {
        if (c.last_stats && system && last_system_) {
          c.cpu_usage = JiffyFraction(c.last_stats->cpu_jiffies, stats->cpu_jiffies,
                                      last_system_->total_jiffies, system->total_jiffies);
        }
        report.mem_vsize_bytes = stats->vsize_bytes;
        report.mem_rss_bytes = stats->rss_bytes;
      }
      c.last_stats = stats;
      report.cpu_usage = c.cpu_usage;
    } else {
      c.last_stats.reset();
      c.cpu_usage = 0.0f;
    }
    info.cmds.push_back(std::move(report));
  }
  if (system) last_system_ = system;
  return info;
}

void DeputyNode::StopAll() {
  stopping_all_ = true;
  for (auto& [id, c] : commands_) Reconcile(&c);
}

bool DeputyNode::IsIdle() const {
  for (const auto& [id, c] : commands_) {
    if (c.runner && !c.runner->IsIdle()) return false;
  }
  return true;
}

}  // namespace vimot::deputy

#include "procs/sheriff/remote_commands.h"

#include <set>
#include <stdexcept>
#include <utility>

namespace vimot::sheriff {

RemoteCommands::RemoteCommands(const SheriffConfig& config, RemoteOptions options)
    : options_(std::move(options)) {
  if (options_.sheriff_name.empty()) {
    throw std::invalid_argument("RemoteCommands: empty sheriff name");
  }
  if (options_.local_host.empty()) {
    throw std::invalid_argument("RemoteCommands: empty local host name");
  }
  int32_t next_id = 1;
  for (const CommandSpec& spec : config.commands()) {
    Remote r;
    r.spec = spec;
    const bool local = spec.host.empty() || spec.host == "localhost" ||
                       spec.host == "127.0.0.1";
    r.host = local ? options_.local_host : spec.host;
    r.sheriff_id = next_id++;
    index_.emplace(spec.name, remotes_.size());
    remotes_.push_back(std::move(r));
  }
}

RemoteCommands::Remote& RemoteCommands::Find(const std::string& name) {
  const auto it = index_.find(name);
  if (it == index_.end()) throw std::invalid_argument("unknown command '" + name + "'");
  return remotes_[it->second];
}

const RemoteCommands::Remote& RemoteCommands::Find(const std::string& name) const {
  const auto it = index_.find(name);
  if (it == index_.end()) throw std::invalid_argument("unknown command '" + name + "'");
  return remotes_[it->second];
}

void RemoteCommands::Start(const std::string& name) {
  Remote& r = Find(name);
  // Running the current run already: nothing to do (ProcessRunner::Start
  // semantics). Otherwise a new run id makes the deputy start it.
  if (r.state.status == CommandStatus::kRunning && !r.force_quit) return;
  if (!r.force_quit && r.state.status == CommandStatus::kRespawnPending) return;
  ++r.desired_runid;
  r.force_quit = false;
  orders_changed_ = true;
  UpdateState(&r);
}

void RemoteCommands::Stop(const std::string& name) {
  Remote& r = Find(name);
  if (r.force_quit) return;
  r.force_quit = true;
  orders_changed_ = true;
  UpdateState(&r);
}

void RemoteCommands::Restart(const std::string& name) {
  Remote& r = Find(name);
  ++r.desired_runid;
  r.force_quit = false;
  orders_changed_ = true;
  UpdateState(&r);
}

bool RemoteCommands::IsLocal(const std::string& name) const {
  Find(name);
  return true;
}

const CommandState& RemoteCommands::state(const std::string& name) const {
  return Find(name).state;
}

const std::string& RemoteCommands::HostOf(const std::string& name) const {
  return Find(name).host;
}

std::vector<DeputyOrders> RemoteCommands::Orders(int64_t now_utime) const {
  std::map<std::string, DeputyOrders> by_host;
  for (const Remote& r : remotes_) {
    DeputyOrders& orders = by_host[r.host];
    orders.utime = now_utime;
    orders.host = r.host;
    orders.sheriff_name = options_.sheriff_name;
    orders.cmds.push_back(
        {ToProcmanCommand(r.spec), r.desired_runid, r.force_quit, r.sheriff_id});
  }
  std::vector<DeputyOrders> out;
  for (auto& [host, orders] : by_host) out.push_back(std::move(orders));
  return out;
}

bool RemoteCommands::OnInfo(const DeputyInfo& info) {
  last_info_utime_[info.host] = info.utime;
  bool changed = false;
  for (Remote& r : remotes_) {
    if (r.host != info.host) continue;
    for (const CommandReport& report : info.cmds) {
      if (report.sheriff_id != r.sheriff_id) continue;
      const CommandStatus before = r.state.status;
      const pid_t pid_before = r.state.pid;
      const bool was_running = r.report && r.report->pid > 0;
      const bool new_run = report.actual_runid != (r.report ? r.report->actual_runid : 0);
      if (report.pid > 0 && (!r.report || r.report->pid != report.pid)) {
        ++r.state.start_count;
        if (r.report && !new_run) ++r.state.respawn_count;
      }
      // A run ended: one seen alive, or one that started and ended between
      // two reports (a command that fails at once).
      const bool ended_unseen = report.pid == 0 && !was_running && new_run;
      if (ended_unseen) ++r.state.start_count;
      if ((was_running && report.pid != r.report->pid) || ended_unseen) {
        ++r.state.exit_count;
        r.state.last_exit = DecodeWaitStatus(report.exit_code);
      }
      r.report = report;
      UpdateState(&r);
      changed |= r.state.status != before || r.state.pid != pid_before;
    }
  }
  return changed;
}

void RemoteCommands::UpdateState(Remote* r) {
  CommandState& s = r->state;
  const CommandReport* report = r->report ? &*r->report : nullptr;
  const bool alive = report != nullptr && report->pid > 0;
  s.pid = alive ? report->pid : -1;
  const bool current_run = report != nullptr && report->actual_runid == r->desired_runid;
  if (alive) {
    s.status = r->force_quit || !current_run ? CommandStatus::kStopping
                                             : CommandStatus::kRunning;
  } else if (r->force_quit) {
    s.status = CommandStatus::kStopped;
  } else if (!current_run) {
    s.status = CommandStatus::kRespawnPending;  // start asked for, not seen yet
  } else if (r->spec.auto_respawn) {
    s.status = CommandStatus::kRespawnPending;
  } else {
    s.status = CommandStatus::kExited;
  }
}

std::optional<std::string> RemoteCommands::NameOf(const std::string& host,
                                                 int32_t sheriff_id) const {
  for (const Remote& r : remotes_) {
    if (r.host == host && r.sheriff_id == sheriff_id) return r.spec.name;
  }
  return std::nullopt;
}

std::vector<std::string> RemoteCommands::SeenHosts() const {
  std::vector<std::string> hosts;
  for (const auto& [host, utime] : last_info_utime_) hosts.push_back(host);
  return hosts;
}

void RemoteCommands::StopAll() {
  for (Remote& r : remotes_) Stop(r.spec.name);
}

bool RemoteCommands::AllStopped() const {
  for (const Remote& r : remotes_) {
    const CommandStatus s = r.state.status;
    if (s == CommandStatus::kRunning || s == CommandStatus::kStopping ||
        s == CommandStatus::kRespawnPending) {
      return false;
    }
  }
  return true;
}

bool RemoteCommands::TakeOrdersChanged() {
  return std::exchange(orders_changed_, false);
}

std::vector<std::string> RemoteCommands::command_names() const {
  std::vector<std::string> names;
  for (const Remote& r : remotes_) names.push_back(r.spec.name);
  return names;
}

}  // namespace vimot::sheriff

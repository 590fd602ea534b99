#pragma once
// The sheriff's half of procman's deputy protocol, without LCM: keeps what
// the user asked of each command (desired run id, force_quit), builds the
// orders for each host's deputy, and follows the deputies' info to know
// each command's actual state. vimot-sheriff --lcm publishes Orders() and
// feeds OnInfo(); scripts drive it through CommandControl.

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "procs/sheriff/command_control.h"
#include "procs/sheriff/procman_protocol.h"
#include "procs/sheriff/process_runner.h"
#include "procs/sheriff/sheriff_config.h"

namespace vimot::sheriff {

struct RemoteOptions {
  /// orders2_t.sheriff_name; deputies report whose orders they obey.
  std::string sheriff_name;
  /// Deputy of commands whose host is "localhost", "127.0.0.1" or empty
  /// (usually this machine's name, which its deputy answers to).
  std::string local_host;
};

/// Command states seen through a deputy's info (CommandState::status):
///  * kRunning: the deputy runs the current run id (pid != 0);
///  * kStopping: it still runs, but stopped or restarted was asked for;
///  * kRespawnPending: a start was asked for and the deputy has not reported
///    the new run yet, or it exited and will be respawned (auto_respawn);
///  * kStopped: stopped on request (or never started);
///  * kExited: the current run ended on its own (last_exit says how).
/// start_count / exit_count count runs seen starting and ending.
class RemoteCommands : public CommandControl {
 public:
  /// Sheriff ids are 1, 2, ... in config order. Throws std::invalid_argument
  /// for an empty sheriff_name or local_host.
  RemoteCommands(const SheriffConfig& config, RemoteOptions options);

  void Start(const std::string& name) override;
  void Stop(const std::string& name) override;
  void Restart(const std::string& name) override;
  /// Every command of the config is run by some deputy.
  bool IsLocal(const std::string& name) const override;
  const CommandState& state(const std::string& name) const override;

  /// One orders message per host (deputy), in host name order.
  std::vector<DeputyOrders> Orders(int64_t now_utime) const;
  /// Updates the state of the commands `info.host` reports (matched by
  /// sheriff id). Returns true if a state changed.
  bool OnInfo(const DeputyInfo& info);

  /// The deputy a command runs on.
  const std::string& HostOf(const std::string& name) const;
  /// The command `host`'s deputy runs as `sheriff_id`, if it is ours.
  std::optional<std::string> NameOf(const std::string& host, int32_t sheriff_id) const;
  /// Hosts whose deputy has sent info.
  std::vector<std::string> SeenHosts() const;
  /// Stop every command.
  void StopAll();
  /// True when no command is running or waiting for a (re)start.
  bool AllStopped() const;
  /// True once orders changed since the last call (publish them now).
  bool TakeOrdersChanged();
  std::vector<std::string> command_names() const;

 private:
  struct Remote {
    CommandSpec spec;
    std::string host;
    int32_t sheriff_id{0};
    int32_t desired_runid{0};
    bool force_quit{true};
    std::optional<CommandReport> report;
    CommandState state;
  };
  Remote& Find(const std::string& name);
  const Remote& Find(const std::string& name) const;
  void UpdateState(Remote* r);

  RemoteOptions options_;
  std::vector<Remote> remotes_;
  std::map<std::string, std::size_t> index_;
  std::map<std::string, int64_t> last_info_utime_;
  bool orders_changed_{true};
};

}  // namespace vimot::sheriff

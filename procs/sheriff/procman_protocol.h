#pragma once
// libbot2 procman's deputy protocol in plain C++ (no LCM): the content of
// bot_procman orders2_t, info2_t and printf_t, which procman_lcm.h converts
// to and from the wire types in lcmtypes/procman/. The protocol logic
// (DeputyNode, RemoteCommands) works on these, so tests drive it without a
// network.
//
// Channels: PMD_ORDERS2 (sheriff -> deputies), PMD_INFO2 (deputy -> sheriff,
// once a second and after every change), PMD_PRINTF (command output),
// PMD_DISCOVER (discovery; a deputy answers with its info).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "procs/sheriff/process_runner.h"
#include "procs/sheriff/sheriff_config.h"

namespace vimot::sheriff {

inline constexpr char kOrdersChannel[] = "PMD_ORDERS2";
inline constexpr char kInfoChannel[] = "PMD_INFO2";
inline constexpr char kPrintfChannel[] = "PMD_PRINTF";
inline constexpr char kDiscoverChannel[] = "PMD_DISCOVER";

/// command2_t: what to run. stop_time_allowed in seconds, as on the wire.
struct ProcmanCommand {
  std::string exec;
  std::string name;
  std::string group;
  bool auto_respawn{false};
  int stop_signal{kDefaultStopSignal};
  double stop_time_allowed_s{7.0};

  bool operator==(const ProcmanCommand& o) const {
    return exec == o.exec && name == o.name && group == o.group &&
           auto_respawn == o.auto_respawn && stop_signal == o.stop_signal &&
           stop_time_allowed_s == o.stop_time_allowed_s;
  }
  bool operator!=(const ProcmanCommand& o) const { return !(*this == o); }
};

/// The command of a config entry, and back (host "localhost": a deputy runs
/// whatever it is sent on its own machine).
ProcmanCommand ToProcmanCommand(const CommandSpec& spec);
CommandSpec ToCommandSpec(const ProcmanCommand& cmd);

/// sheriff_cmd2_t.
struct CommandOrder {
  ProcmanCommand cmd;
  /// The deputy (re)starts the command whenever this differs from the run id
  /// it last started, unless force_quit.
  int32_t desired_runid{0};
  bool force_quit{false};
  /// The sheriff's key for the command.
  int32_t sheriff_id{0};
};

/// orders2_t.
struct DeputyOrders {
  int64_t utime{0};
  std::string host;
  std::string sheriff_name;
  std::vector<CommandOrder> cmds;
};

/// deputy_cmd2_t.
struct CommandReport {
  ProcmanCommand cmd;
  /// 0 when not running.
  int32_t pid{0};
  int32_t actual_runid{0};
  /// Last wait() status, encoded like waitpid(): code << 8, or the signal.
  int32_t exit_code{0};
  float cpu_usage{0.0f};
  int64_t mem_vsize_bytes{0};
  int64_t mem_rss_bytes{0};
  int32_t sheriff_id{0};
};

/// info2_t.
struct DeputyInfo {
  int64_t utime{0};
  std::string host;
  float cpu_load{0.0f};
  int64_t phys_mem_total_bytes{0};
  int64_t phys_mem_free_bytes{0};
  int64_t swap_total_bytes{0};
  int64_t swap_free_bytes{0};
  std::vector<CommandReport> cmds;
};

/// printf_t: one chunk of output of command `sheriff_id` (0: the deputy's own).
struct DeputyOutput {
  int64_t utime{0};
  std::string deputy_name;
  int32_t sheriff_id{0};
  std::string text;
};

}  // namespace vimot::sheriff

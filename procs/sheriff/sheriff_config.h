#pragma once
// The in-memory form of a libbot2 procman ("bot-procman-sheriff") config:
// commands, (nested) groups and scripts. Parsing lives in
// sheriff_config_parser.h; running lives in process_runner.h.

#include <chrono>
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace vimot::sheriff {

/// Where something was written in a config file; line and column are 1-based.
struct SourceLocation {
  std::string file;
  int line{0};
  int column{0};

  /// "file:line:column".
  std::string ToString() const;
};

/// procman's defaults: SIGINT (2), which most programs treat as "shut down
/// cleanly", and 7 s before the sheriff gives up and sends SIGKILL.
constexpr int kDefaultStopSignal = 2;
/// Limits that keep a hostile or generated config from exhausting the stack
/// or memory (a group path is stored per level, so depth costs depth^2):
/// groups nest at most this deep, and run_script chains at most this long.
constexpr int kMaxGroupDepth = 32;
constexpr int kMaxScriptNesting = 64;
constexpr std::chrono::milliseconds kDefaultStopTimeAllowed{7000};

/// One `cmd "name" { ... }` block.
struct CommandSpec {
  /// Unique over the config; used in scripts and as the output prefix.
  std::string name;
  /// Shell command line, run with `/bin/sh -c` after environment expansion.
  std::string exec;
  /// Machine the command belongs to; only local commands are started here.
  std::string host{"localhost"};
  /// Full group path ("0.sensors/imu"), empty for a top-level command.
  std::string group;
  /// Start the command again (with back-off) whenever it exits on its own.
  bool auto_respawn{false};
  /// Signal sent to the command's process group to stop it.
  int stop_signal{kDefaultStopSignal};
  /// Time between stop_signal and SIGKILL.
  std::chrono::milliseconds stop_time_allowed{kDefaultStopTimeAllowed};
  /// Attributes this sheriff does not know, in file order, kept so a config
  /// written for another procman version still loads (reported as warnings).
  std::vector<std::pair<std::string, std::string>> extra_attributes;
  SourceLocation location;
};

/// One group; `group "a" { group "b" {} }` defines "a" and "a/b". Dots are
/// ordinary name characters ("0.sensors"); '/' separates nesting levels.
struct GroupSpec {
  /// Full path, e.g. "0.sensors/imu".
  std::string name;
  /// Names of the commands directly in this group, in file order.
  std::vector<std::string> commands;
  /// Full paths of the direct subgroups, in file order.
  std::vector<std::string> subgroups;
  SourceLocation location;
};

enum class ActionKind { kStart, kStop, kRestart, kWaitMs, kWaitStatus, kRunScript };
enum class ActionTarget { kCommand, kGroup, kEverything, kScript, kNone };
enum class WaitStatus { kNone, kRunning, kStopped };

/// "running" / "stopped" / "" for kNone.
const char* ToString(WaitStatus status);

/// One statement of a script:
///   start|stop|restart cmd "x"|group "g"|everything [wait "running"|"stopped"];
///   wait ms N;
///   wait cmd "x"|group "g" status "running"|"stopped";
///   run_script "name";
struct ScriptAction {
  ActionKind kind{ActionKind::kStart};
  /// kCommand / kGroup / kEverything for start, stop, restart and wait status;
  /// kScript for run_script; kNone for wait ms.
  ActionTarget target{ActionTarget::kNone};
  /// Command name, full group path or script name; empty otherwise.
  std::string name;
  /// For start/stop/restart: the optional `wait`; for wait status: required.
  WaitStatus wait{WaitStatus::kNone};
  /// For wait ms.
  std::chrono::milliseconds delay{0};
  SourceLocation location;

  /// The action in config syntax, e.g. `start cmd "sim" wait "running";`.
  std::string ToString() const;
};

/// One `script "name" { ... }` block.
struct ScriptSpec {
  std::string name;
  std::vector<ScriptAction> actions;
  SourceLocation location;
};

/// Something legal but suspicious in a config (an unknown attribute).
struct ConfigWarning {
  SourceLocation location;
  std::string message;

  /// "file:line:column: warning: message".
  std::string ToString() const;
};

/// A whole config. Built by the parser; read-only for everyone else.
class SheriffConfig {
 public:
  /// Adds a command and every group on the path to its group. Throws
  /// std::invalid_argument if the name is empty or already used.
  void AddCommand(CommandSpec command);
  /// Creates the group `full_name` and its parents if they do not exist yet
  /// (a group may be opened more than once; the blocks merge). Throws
  /// std::invalid_argument on an empty path or one deeper than
  /// kMaxGroupDepth.
  void AddGroup(const std::string& full_name, const SourceLocation& location);
  /// Throws std::invalid_argument if the name is empty or already used.
  void AddScript(ScriptSpec script);
  void AddWarning(ConfigWarning warning);

  /// In file order.
  const std::vector<CommandSpec>& commands() const { return commands_; }
  /// In file order of first appearance; a parent precedes its subgroups.
  const std::vector<GroupSpec>& groups() const { return groups_; }
  const std::vector<ScriptSpec>& scripts() const { return scripts_; }
  const std::vector<ConfigWarning>& warnings() const { return warnings_; }

  /// nullptr when there is no such command / group / script.
  const CommandSpec* FindCommand(const std::string& name) const;
  const GroupSpec* FindGroup(const std::string& full_name) const;
  const ScriptSpec* FindScript(const std::string& name) const;

  /// Commands of `group` and of all its subgroups, in file order (the order
  /// procman starts them in). Throws std::invalid_argument for an unknown
  /// group.
  std::vector<std::string> CommandsInGroup(const std::string& group) const;

  /// Normalises a group path: no leading, trailing or doubled '/'.
  static std::string NormalizeGroupName(const std::string& name);
  /// Levels of a normalised group path ("a/b" = 2).
  static int GroupDepth(const std::string& normalized_name);

 private:
  std::vector<CommandSpec> commands_;
  std::vector<GroupSpec> groups_;
  std::vector<ScriptSpec> scripts_;
  std::vector<ConfigWarning> warnings_;
  std::map<std::string, std::size_t> command_index_;
  std::map<std::string, std::size_t> group_index_;
  std::map<std::string, std::size_t> script_index_;
};

/// Human-readable listing of groups, commands and scripts (`--list`).
std::string DescribeConfig(const SheriffConfig& config);

}  // namespace vimot::sheriff

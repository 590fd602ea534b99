#include "procs/sheriff/sheriff_config.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace vimot::sheriff {

namespace {

// Quotes `text` the way the config format writes strings.
std::string QuoteString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out.push_back('\\');
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else {
      out.push_back(c);
    }
  }
  out.push_back('"');
  return out;
}

const char* TargetKeyword(ActionTarget target) {
  switch (target) {
    case ActionTarget::kCommand:
      return "cmd";
    case ActionTarget::kGroup:
      return "group";
    case ActionTarget::kEverything:
      return "everything";
    case ActionTarget::kScript:
      return "script";
    case ActionTarget::kNone:
      break;
  }
  return "";
}

std::string FormatDuration(std::chrono::milliseconds d) {
  std::ostringstream out;
  if (d.count() % 1000 == 0) {
    out << d.count() / 1000 << " s";
  } else {
    out << d.count() << " ms";
  }
  return out.str();
}

void DescribeCommand(const CommandSpec& c, const std::string& indent,
                     std::ostringstream* out) {
  *out << indent << "cmd " << QuoteString(c.name) << "  host=" << c.host
       << (c.auto_respawn ? " auto_respawn" : "")
       << " stop_signal=" << c.stop_signal
       << " stop_time_allowed=" << FormatDuration(c.stop_time_allowed) << "\n";
  *out << indent << "    exec: " << c.exec << "\n";
  for (const auto& [key, value] : c.extra_attributes) {
    *out << indent << "    (unknown) " << key << " = " << QuoteString(value)
         << "\n";
  }
}

void DescribeGroup(const SheriffConfig& config, const GroupSpec& group,
                   const std::string& indent, std::ostringstream* out) {
  *out << indent << "group " << QuoteString(group.name) << "\n";
  for (const std::string& sub : group.subgroups) {
    DescribeGroup(config, *config.FindGroup(sub), indent + "  ", out);
  }
  for (const std::string& name : group.commands) {
    DescribeCommand(*config.FindCommand(name), indent + "  ", out);
  }
}

}  // namespace

std::string SourceLocation::ToString() const {
  return file + ":" + std::to_string(line) + ":" + std::to_string(column);
}

const char* ToString(WaitStatus status) {
  switch (status) {
    case WaitStatus::kRunning:
      return "running";
    case WaitStatus::kStopped:
      return "stopped";
    case WaitStatus::kNone:
      break;
  }
  return "";
}

std::string ScriptAction::ToString() const {
  std::ostringstream out;
  const auto target_text = [this]() {
    std::string text = TargetKeyword(target);
    if (target != ActionTarget::kEverything) text += " " + QuoteString(name);
    return text;
  };
  switch (kind) {
    case ActionKind::kStart:
    case ActionKind::kStop:
    case ActionKind::kRestart:
      out << (kind == ActionKind::kStart  ? "start"
              : kind == ActionKind::kStop ? "stop"
                                          : "restart")
          << " " << target_text();
      if (wait != WaitStatus::kNone) {
        out << " wait " << QuoteString(sheriff::ToString(wait));
      }
      break;
    case ActionKind::kWaitMs:
      out << "wait ms " << delay.count();
      break;
    case ActionKind::kWaitStatus:
      out << "wait " << target_text() << " status "
          << QuoteString(sheriff::ToString(wait));
      break;
    case ActionKind::kRunScript:
      out << "run_script " << QuoteString(name);
      break;
  }
  out << ";";
  return out.str();
}

std::string ConfigWarning::ToString() const {
  return location.ToString() + ": warning: " + message;
}

std::string SheriffConfig::NormalizeGroupName(const std::string& name) {
  std::string out;
  for (const char c : name) {
    if (c == '/' && (out.empty() || out.back() == '/')) continue;
    out.push_back(c);
  }
  if (!out.empty() && out.back() == '/') out.pop_back();
  return out;
}

int SheriffConfig::GroupDepth(const std::string& normalized_name) {
  if (normalized_name.empty()) return 0;
  return 1 + static_cast<int>(std::count(normalized_name.begin(), normalized_name.end(), '/'));
}

void SheriffConfig::AddCommand(CommandSpec command) {
  if (command.name.empty()) {
    throw std::invalid_argument("SheriffConfig: a command needs a name");
  }
  if (command_index_.count(command.name) > 0) {
    throw std::invalid_argument("SheriffConfig: duplicate command name '" +
                                command.name + "'");
  }
  command.group = NormalizeGroupName(command.group);
  if (!command.group.empty()) {
    AddGroup(command.group, command.location);
    groups_[group_index_.at(command.group)].commands.push_back(command.name);
  }
  command_index_[command.name] = commands_.size();
  commands_.push_back(std::move(command));
}

void SheriffConfig::AddGroup(const std::string& full_name,
                             const SourceLocation& location) {
  const std::string name = NormalizeGroupName(full_name);
  if (name.empty()) {
    throw std::invalid_argument("SheriffConfig: empty group name '" +
                                full_name + "'");
  }
  if (group_index_.count(name) > 0) return;
  if (GroupDepth(name) > kMaxGroupDepth) {
    throw std::invalid_argument("SheriffConfig: group '" + name.substr(0, 60) + "...' nests " +
                                std::to_string(GroupDepth(name)) + " levels deep; at most " +
                                std::to_string(kMaxGroupDepth) + " are allowed");
  }
  const std::size_t slash = name.rfind('/');
  if (slash != std::string::npos) {
    const std::string parent = name.substr(0, slash);
    AddGroup(parent, location);
    groups_[group_index_.at(parent)].subgroups.push_back(name);
  }
  GroupSpec group;
  group.name = name;
  group.location = location;
  group_index_[name] = groups_.size();
  groups_.push_back(std::move(group));
}

void SheriffConfig::AddScript(ScriptSpec script) {
  if (script.name.empty()) {
    throw std::invalid_argument("SheriffConfig: a script needs a name");
  }
  if (script_index_.count(script.name) > 0) {
    throw std::invalid_argument("SheriffConfig: duplicate script name '" +
                                script.name + "'");
  }
  script_index_[script.name] = scripts_.size();
  scripts_.push_back(std::move(script));
}

void SheriffConfig::AddWarning(ConfigWarning warning) {
  warnings_.push_back(std::move(warning));
}

const CommandSpec* SheriffConfig::FindCommand(const std::string& name) const {
  const auto it = command_index_.find(name);
  return it == command_index_.end() ? nullptr : &commands_[it->second];
}

const GroupSpec* SheriffConfig::FindGroup(const std::string& full_name) const {
  const auto it = group_index_.find(NormalizeGroupName(full_name));
  return it == group_index_.end() ? nullptr : &groups_[it->second];
}

const ScriptSpec* SheriffConfig::FindScript(const std::string& name) const {
  const auto it = script_index_.find(name);
  return it == script_index_.end() ? nullptr : &scripts_[it->second];
}

std::vector<std::string> SheriffConfig::CommandsInGroup(
    const std::string& group) const {
  const GroupSpec* spec = FindGroup(group);
  if (spec == nullptr) {
    throw std::invalid_argument("SheriffConfig: unknown group '" + group + "'");
  }
  const std::string prefix = spec->name + "/";
  std::vector<std::string> names;
  for (const CommandSpec& c : commands_) {
    if (c.group == spec->name || c.group.compare(0, prefix.size(), prefix) == 0) {
      names.push_back(c.name);
    }
  }
  return names;
}

std::string DescribeConfig(const SheriffConfig& config) {
  std::ostringstream out;
  out << "commands (" << config.commands().size() << "):\n";
  for (const GroupSpec& group : config.groups()) {
    if (group.name.find('/') == std::string::npos) {
      DescribeGroup(config, group, "  ", &out);
    }
  }
  for (const CommandSpec& c : config.commands()) {
    if (c.group.empty()) DescribeCommand(c, "  ", &out);
  }
  out << "scripts (" << config.scripts().size() << "):\n";
  for (const ScriptSpec& script : config.scripts()) {
    out << "  script " << QuoteString(script.name) << "\n";
    for (const ScriptAction& action : script.actions) {
      out << "    " << action.ToString() << "\n";
    }
  }
  return out.str();
}

}  // namespace vimot::sheriff

#pragma once
// Parser for the libbot2 procman ("bot-procman-sheriff", .pmd) config format:
//
//   # comment to end of line
//   group "0.sensors" {                 # groups nest; "a" { group "b" } = "a/b"
//     cmd "sim" {
//       exec = "${VIMOT_BIN}/vimot-sim --speed 2";   # required
//       host = "localhost";             # default "localhost"
//       auto_respawn = "true";          # "true" | "false", default "false"
//       stop_signal = 15;               # 1..NSIG-1, default 2 (SIGINT)
//       stop_time_allowed = 5;          # seconds >= 1, default 7
//     }
//   }
//   cmd "logger" { exec = "lcm-logger -f out.lcm"; group = "1.logging"; }
//   script "start_all" {
//     start group "0.sensors";          # start|stop|restart cmd|group|everything
//     wait ms 500;
//     start cmd "logger" wait "running";
//     wait cmd "sim" status "stopped";  # wait cmd|group "x" status "..."
//     run_script "other";
//   }
//
// Strings are double-quoted with backslash escapes (\" \\ \n \t \r; any other
// escaped character stands for itself). Integers may also be given as
// strings. Unknown cmd attributes are kept and reported as warnings.

#include <stdexcept>
#include <string>
#include <string_view>

#include "procs/sheriff/sheriff_config.h"

namespace vimot::sheriff {

/// A config that is not well formed. what() reads
/// "file:line:column: error: <what was expected, and what was found>"
/// followed by the offending source line and a caret under the column.
class ConfigParseError : public std::runtime_error {
 public:
  ConfigParseError(SourceLocation location, const std::string& message,
                   const std::string& source_line);

  const SourceLocation& location() const { return location_; }
  /// The message without location or source excerpt.
  const std::string& message() const { return message_; }

 private:
  SourceLocation location_;
  std::string message_;
};

/// Parses config text; `file_name` is only used in error locations. Also
/// checks that every script refers to existing commands, groups and scripts
/// and that run_script does not recurse. Throws ConfigParseError.
SheriffConfig ParseSheriffConfig(std::string_view text,
                                 const std::string& file_name);

/// Reads and parses a config file. Throws std::runtime_error if the file
/// cannot be read and ConfigParseError if it is not well formed.
SheriffConfig LoadSheriffConfig(const std::string& path);

}  // namespace vimot::sheriff

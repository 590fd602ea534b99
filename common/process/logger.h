#pragma once
// One log line format for every vimot process, on stderr:
//   2026-11-21 10:00:00.123 [vins] WARN: dropped IMU sample (time went backwards)
// Thread-safe; the level filter is process-wide.

#include <sstream>
#include <string>

namespace vimot {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

/// Parses "debug|info|warn|error"; throws std::invalid_argument otherwise.
LogLevel parse_log_level(const std::string& text);
void set_log_level(LogLevel level);
void set_log_name(const std::string& name);
void log_line(LogLevel level, const std::string& message);

namespace detail {
template <typename... Args>
std::string concat(const Args&... args) {
  std::ostringstream s;
  (s << ... << args);
  return s.str();
}
}  // namespace detail

template <typename... Args>
void log_debug(const Args&... args) { log_line(LogLevel::kDebug, detail::concat(args...)); }
template <typename... Args>
void log_info(const Args&... args) { log_line(LogLevel::kInfo, detail::concat(args...)); }
template <typename... Args>
void log_warn(const Args&... args) { log_line(LogLevel::kWarn, detail::concat(args...)); }
template <typename... Args>
void log_error(const Args&... args) { log_line(LogLevel::kError, detail::concat(args...)); }

}  // namespace vimot

#pragma once
// One log line format for every vimot process, on stderr:
//   2026-11-21 10:00:00.123 [vins] WARN: dropped IMU sample (time went backwards)
// Thread-safe; the level filter is process-wide.
//
// WARN and ERROR lines are rate-limited per shape (the text with each run of
// digits read as one wildcard), so one bad input repeated at sensor rate
// cannot flood the log: per shape, the first `burst` lines of each window are
// written and the rest counted, then reported in one line. INFO and DEBUG are
// not limited: they are progress the user asked for.

#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace vimot {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarn = 2, kError = 3 };

/// Parses "debug|info|warn|error"; throws std::invalid_argument otherwise.
LogLevel parse_log_level(const std::string& text);
void set_log_level(LogLevel level);
void set_log_name(const std::string& name);
void log_line(LogLevel level, const std::string& message);

/// Per shape and window of `window_s` seconds, `burst` WARN/ERROR lines are
/// written (defaults: 5 per 10 s).
void set_log_rate_limit(int burst, double window_s);
/// Writes the count of lines suppressed in every window that has ended
/// (Process::run calls it with each heartbeat and when it stops).
void flush_suppressed_logs();

/// The rate limiter behind log_line, on an explicit clock (seconds).
class LogRateLimiter {
 public:
  LogRateLimiter(int burst, double window_s) : burst_(burst), window_s_(window_s) {}

  struct Decision {
    bool write{false};
    /// Lines of this shape suppressed in its previous window, reported with
    /// this one (0 if none).
    int64_t suppressed_before{0};
    double suppressed_over_s{0};
  };
  Decision admit(const std::string& message, double now_s);

  struct Summary {
    std::string last_message;  // the last suppressed line, as an example
    int64_t suppressed{0};
    double over_s{0};
  };
  /// Suppressed counts of the windows that have ended by now_s, once each.
  std::vector<Summary> take_ended(double now_s);

  /// `message` with each run of digits replaced by '#'.
  static std::string shape(const std::string& message);

 private:
  struct Window {
    double start_s{0};
    int written{0};
    int64_t suppressed{0};
    std::string last_suppressed;
  };
  int burst_;
  double window_s_;
  std::map<std::string, Window> windows_;
};

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

#include "common/process/logger.h"

#include <atomic>
#include <cctype>
#include <chrono>
#include <ctime>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <stdexcept>

namespace vimot {

namespace {
std::atomic<int> g_level{static_cast<int>(LogLevel::kInfo)};
std::mutex g_mutex;
// Guarded by g_mutex:
std::string g_name = "vimot";
LogRateLimiter g_warn_limiter{5, 10.0};
LogRateLimiter g_error_limiter{5, 10.0};
double g_next_sweep_s = 0;  // ended windows are reported and dropped by then

const char* level_name(LogLevel level) {
  switch (level) {
    case LogLevel::kDebug: return "DEBUG";
    case LogLevel::kInfo: return "INFO";
    case LogLevel::kWarn: return "WARN";
    case LogLevel::kError: return "ERROR";
  }
  return "?";
}

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Caller holds g_mutex.
void write_line(LogLevel level, const std::string& message) {
  const auto now = std::chrono::system_clock::now();
  const std::time_t secs = std::chrono::system_clock::to_time_t(now);
  const auto millis =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm local{};
  localtime_r(&secs, &local);
  std::cerr << std::put_time(&local, "%Y-%m-%d %H:%M:%S") << '.' << std::setw(3) << std::setfill('0') << millis
            << std::setfill(' ') << " [" << g_name << "] " << level_name(level) << ": " << message << std::endl;
}

// Caller holds g_mutex.
void write_summaries(LogLevel level, LogRateLimiter& limiter, double now_s) {
  for (const LogRateLimiter::Summary& s : limiter.take_ended(now_s)) {
    write_line(level, detail::concat(s.suppressed, " similar lines suppressed in ", std::setprecision(3), s.over_s,
                                     " s, the last: ", s.last_message));
  }
}
}  // namespace

LogLevel parse_log_level(const std::string& text) {
  if (text == "debug") return LogLevel::kDebug;
  if (text == "info") return LogLevel::kInfo;
  if (text == "warn") return LogLevel::kWarn;
  if (text == "error") return LogLevel::kError;
  throw std::invalid_argument("log level must be debug, info, warn or error, got '" + text + "'");
}

void set_log_level(LogLevel level) { g_level = static_cast<int>(level); }

void set_log_name(const std::string& name) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_name = name;
}

void set_log_rate_limit(int burst, double window_s) {
  std::lock_guard<std::mutex> lock(g_mutex);
  g_warn_limiter = LogRateLimiter(burst, window_s);
  g_error_limiter = LogRateLimiter(burst, window_s);
}

void flush_suppressed_logs() {
  const double now_s = steady_seconds();
  std::lock_guard<std::mutex> lock(g_mutex);
  write_summaries(LogLevel::kWarn, g_warn_limiter, now_s);
  write_summaries(LogLevel::kError, g_error_limiter, now_s);
}

void log_line(LogLevel level, const std::string& message) {
  if (static_cast<int>(level) < g_level) return;
  std::lock_guard<std::mutex> lock(g_mutex);
  if (level < LogLevel::kWarn) {
    write_line(level, message);
    return;
  }
  const double now_s = steady_seconds();
  if (now_s >= g_next_sweep_s) {  // also bounds the limiters' memory
    write_summaries(LogLevel::kWarn, g_warn_limiter, now_s);
    write_summaries(LogLevel::kError, g_error_limiter, now_s);
    g_next_sweep_s = now_s + 1.0;
  }
  LogRateLimiter& limiter = level == LogLevel::kWarn ? g_warn_limiter : g_error_limiter;
  const LogRateLimiter::Decision d = limiter.admit(message, now_s);
  if (!d.write) return;
  if (d.suppressed_before == 0) {
    write_line(level, message);
  } else {
    write_line(level, detail::concat(message, " (", d.suppressed_before, " similar lines suppressed in the previous ",
                                     std::setprecision(3), d.suppressed_over_s, " s)"));
  }
}

std::string LogRateLimiter::shape(const std::string& message) {
  std::string s;
  s.reserve(message.size());
  for (std::size_t i = 0; i < message.size(); ++i) {
    if (std::isdigit(static_cast<unsigned char>(message[i]))) {
      if (s.empty() || s.back() != '#') s += '#';
    } else {
      s += message[i];
    }
  }
  return s;
}

LogRateLimiter::Decision LogRateLimiter::admit(const std::string& message, double now_s) {
  Window& w = windows_[shape(message)];
  Decision d;
  if (w.written == 0 && w.suppressed == 0) {
    w.start_s = now_s;  // a new shape (or one take_ended() cleared)
  } else if (now_s - w.start_s >= window_s_) {
    d.suppressed_before = w.suppressed;
    d.suppressed_over_s = now_s - w.start_s;
    w = Window{now_s, 0, 0, {}};
  }
  if (w.written < burst_) {
    ++w.written;
    d.write = true;
  } else {
    ++w.suppressed;
    w.last_suppressed = message;
  }
  return d;
}

std::vector<LogRateLimiter::Summary> LogRateLimiter::take_ended(double now_s) {
  std::vector<Summary> out;
  for (auto it = windows_.begin(); it != windows_.end();) {
    const Window& w = it->second;
    if (now_s - w.start_s < window_s_) {
      ++it;
      continue;
    }
    if (w.suppressed > 0) out.push_back(Summary{w.last_suppressed, w.suppressed, now_s - w.start_s});
    it = windows_.erase(it);  // ended: the map holds only shapes of the current window
  }
  return out;
}

}  // namespace vimot

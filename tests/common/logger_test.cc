// Log rate limiting: a repeated WARN/ERROR line is written a few times per
// window, the rest counted and reported; distinct lines are not merged.
#include <catch2/catch.hpp>

#include <chrono>
#include <iostream>
#include <sstream>
#include <thread>

#include "common/process/logger.h"

using vimot::LogRateLimiter;

namespace {
// Captures std::cerr while alive.
class CerrCapture {
 public:
  CerrCapture() : old_(std::cerr.rdbuf(out_.rdbuf())) {}
  ~CerrCapture() { std::cerr.rdbuf(old_); }
  std::vector<std::string> lines() const {
    std::vector<std::string> v;
    std::istringstream in(out_.str());
    for (std::string l; std::getline(in, l);) v.push_back(l);
    return v;
  }

 private:
  std::ostringstream out_;
  std::streambuf* old_;
};
}  // namespace

TEST_CASE("the shape of a line ignores its numbers") {
  CHECK(LogRateLimiter::shape("dropped IMU sample at 1700000000123 (12.5 s late)") ==
        "dropped IMU sample at # (#.# s late)");
  CHECK(LogRateLimiter::shape("no digits") == "no digits");
}

TEST_CASE("a repeated line is written burst times per window, then summarised once") {
  LogRateLimiter lim(3, 10.0);
  int written = 0;
  for (int i = 0; i < 1052; ++i) {
    const auto d = lim.admit("handler error: quat_normalize at utime " + std::to_string(i), 0.001 * i);
    written += d.write;
    CHECK(d.suppressed_before == 0);
  }
  CHECK(written == 3);
  CHECK(lim.take_ended(5.0).empty());  // the window has not ended
  const auto ended = lim.take_ended(10.0);
  REQUIRE(ended.size() == 1);
  CHECK(ended[0].suppressed == 1049);
  CHECK(ended[0].last_message == "handler error: quat_normalize at utime 1051");
  CHECK(lim.take_ended(30.0).empty());  // reported once
  // A new window starts afresh.
  CHECK(lim.admit("handler error: quat_normalize at utime 9", 31.0).write);
}

TEST_CASE("the next line after a window carries the count when nobody took it") {
  LogRateLimiter lim(1, 10.0);
  CHECK(lim.admit("late 1", 0).write);
  CHECK_FALSE(lim.admit("late 2", 1).write);
  CHECK_FALSE(lim.admit("late 3", 2).write);
  const auto d = lim.admit("late 4", 10.5);
  CHECK(d.write);
  CHECK(d.suppressed_before == 2);
  CHECK(d.suppressed_over_s == Approx(10.5));
}

TEST_CASE("different lines are limited separately") {
  LogRateLimiter lim(1, 10.0);
  CHECK(lim.admit("dropped: IMU 1", 0).write);
  CHECK(lim.admit("dropped: FEATURES 1", 0).write);
  CHECK_FALSE(lim.admit("dropped: IMU 2", 0).write);
}

TEST_CASE("log_warn and log_error are rate-limited; info is not") {
  vimot::set_log_level(vimot::LogLevel::kInfo);
  vimot::set_log_rate_limit(5, 0.2);
  std::vector<std::string> lines;
  {
    CerrCapture cap;
    for (int i = 0; i < 8000; ++i) vimot::log_warn("dropped: IMU sample at ", i, " is in the future");
    for (int i = 0; i < 1052; ++i) vimot::log_error("handling IMU: bad gyro ", i);
    for (int i = 0; i < 20; ++i) vimot::log_info("progress ", i);
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    vimot::flush_suppressed_logs();
    lines = cap.lines();
  }
  vimot::set_log_rate_limit(5, 10.0);
  int warn = 0, error = 0, info = 0;
  std::vector<std::string> summaries;
  for (const std::string& l : lines) {
    if (l.find("suppressed") != std::string::npos) {
      summaries.push_back(l);
    } else if (l.find("WARN: dropped: IMU sample at") != std::string::npos) {
      ++warn;
    } else if (l.find("ERROR: handling IMU") != std::string::npos) {
      ++error;
    } else if (l.find("INFO: progress") != std::string::npos) {
      ++info;
    }
  }
  CHECK(warn == 5);
  CHECK(error == 5);
  CHECK(info == 20);
  REQUIRE(summaries.size() == 2);
  CHECK(summaries[0].find("WARN: 7995 similar lines suppressed") != std::string::npos);
  CHECK(summaries[0].find("dropped: IMU sample at 7999 is in the future") != std::string::npos);
  CHECK(summaries[1].find("ERROR: 1047 similar lines suppressed") != std::string::npos);
}

#pragma once
// Helpers shared by the sheriff tests that run real child processes.

#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "procs/sheriff/process_runner.h"

namespace vimot::sheriff::test {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

/// Generous: tests wait on conditions, and a loaded 2-core CI machine can be
/// slow; a passing test never comes near this.
constexpr milliseconds kConditionTimeout{10000};

/// Everything a runner reported, with arrival times.
struct Recorder {
  struct Entry {
    Clock::time_point time;
    std::string text;
  };
  /// "[name] line" for stdout, "[name!] line" for stderr.
  std::vector<Entry> output;
  std::vector<Entry> events;

  RunnerOptions Options() {
    RunnerOptions options;
    options.on_output = [this](const std::string& name, OutputStream stream,
                               const std::string& line) {
      output.push_back({Clock::now(), "[" + name +
                                          (stream == OutputStream::kStderr ? "!" : "") +
                                          "] " + line});
    };
    options.on_event = [this](const std::string& message) {
      events.push_back({Clock::now(), message});
    };
    return options;
  }

  bool HasOutput(const std::string& text) const { return Find(output, text) >= 0; }
  /// Index of the first event containing `text`, -1 if none.
  int EventIndex(const std::string& text) const { return Find(events, text); }
  int CountOutput(const std::string& text) const {
    int n = 0;
    for (const Entry& e : output) n += e.text == text ? 1 : 0;
    return n;
  }
  std::string AllEvents() const {
    std::string all;
    for (const Entry& e : events) all += e.text + "\n";
    return all;
  }

 private:
  static int Find(const std::vector<Entry>& entries, const std::string& text) {
    for (std::size_t i = 0; i < entries.size(); ++i) {
      if (entries[i].text.find(text) != std::string::npos) return static_cast<int>(i);
    }
    return -1;
  }
};

/// Polls `runner` until `done()` or the timeout; returns done().
inline bool PollUntil(ProcessRunner* runner, const std::function<bool()>& done,
                      milliseconds timeout = kConditionTimeout) {
  const Clock::time_point end = Clock::now() + timeout;
  while (!done()) {
    if (Clock::now() > end) return false;
    runner->Poll(milliseconds(20));
  }
  return true;
}

/// A command spec with the fields the runner tests care about.
inline CommandSpec Command(const std::string& name, const std::string& exec) {
  CommandSpec spec;
  spec.name = name;
  spec.exec = exec;
  spec.stop_signal = 15;
  spec.stop_time_allowed = milliseconds(5000);
  return spec;
}

/// A fresh directory under $TMPDIR or /tmp, removed with the object.
class TempDir {
 public:
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base != nullptr ? base : "/tmp") +
                          "/vimot_sheriff_test_XXXXXX";
    if (::mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("mkdtemp failed for " + pattern);
    }
    path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace vimot::sheriff::test

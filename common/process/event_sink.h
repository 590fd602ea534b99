#pragma once
// Where a sensor driver (vimot-sim, vimot-euroc-player) sends its time-ordered
// messages: live LCM paced by a real-time factor, or straight into an LCM log
// file as fast as the CPU allows, with event time = message utime so the
// same input gives the same bytes.

#include <chrono>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "common/process/process.h"

namespace vimot {

class EventSink {
 public:
  virtual ~EventSink() = default;
  virtual void write(const std::string& channel, int64_t utime, const void* data, int size) = 0;
};

/// What an LCM log file holds up to its last whole event.
struct LogFileTail {
  int64_t events{0};          // whole events
  int64_t complete_bytes{0};  // where the last whole event ends
  int64_t file_bytes{0};      // the file's size: more = a half-written event
};

/// Scans the LCM log at `path` event by event (headers only, so a log of
/// any size), resynchronising on the event marker as LCM's reader does.
/// A missing file is an empty one. Throws std::runtime_error if it cannot
/// be read.
LogFileTail scan_log_file(const std::string& path);

class LogFileSink : public EventSink {
 public:
  enum class Mode {
    kReplace,
    /// Go on with an existing log (a respawned logger): a half-written last
    /// event (its writer killed) is cut first, so the next event starts
    /// where a reader expects one (LCM numbers the new events from 0).
    kAppend,
  };
  /// Throws std::runtime_error if `path` cannot be opened for writing.
  /// `flush_each`: every event is in the file when write() returns, so a
  /// respawned estimator can read what it missed (--catch-up-log) while the
  /// run goes on (vimot-logger); off, a driver's offline --log writes fast.
  explicit LogFileSink(const std::string& path, Mode mode = Mode::kReplace, bool flush_each = false);
  void write(const std::string& channel, int64_t utime, const void* data, int size) override;
  /// With kAppend: the log as found (before a half-written event was cut).
  const LogFileTail& found() const { return found_; }

 private:
  LogFileTail found_;
  lcm::LogFile log_;
  bool flush_each_;
};

/// Publishes through the process's LCM handle; with speed > 0 a message of
/// time `utime` leaves (utime - first_utime) / speed after the start (the
/// wall clock decides when, never what); speed 0 = as fast as possible.
/// Sends the process heartbeat at 1 Hz while writing.
class LcmSink : public EventSink {
 public:
  LcmSink(Process& process, double speed, int64_t first_utime, double start_delay_s);
  void write(const std::string& channel, int64_t utime, const void* data, int size) override;

 private:
  Process& process_;
  double speed_;
  int64_t first_utime_;
  std::chrono::steady_clock::time_point wall_start_;
  std::chrono::steady_clock::time_point next_heartbeat_;
};

/// Declares the output options every driver shares: --speed, --start-delay,
/// --log, --linger.
void add_sink_options(ArgParser& args);

/// Declares --clock-file FILE: a paced run whose driver may be restarted
/// mid-run (a sheriff's auto_respawn) goes on as a real sensor would.
void add_clock_file_option(ArgParser& args);

/// The sink those options ask for: the --log file if given, else LCM paced
/// by --speed with `first_utime` leaving after --start-delay. Throws
/// ArgError for a negative --speed.
///
/// `resume`, for a driver that declared --clock-file, receives the utime of
/// the first message to send: `first_utime`, or with --clock-file on a
/// restart within the run (the file holds the wall-clock time the run's
/// first message was due, and the run of `span_s` at --speed has not ended)
/// the utime due now: what fell due while the driver was down is skipped
/// and the rest keeps the first start's schedule. A fresh run (no file, or
/// the file's run has ended) writes the file. Throws ArgError if
/// --clock-file comes with --log or --speed 0, std::runtime_error if the
/// file cannot be written.
std::unique_ptr<EventSink> make_sink(Process& process, int64_t first_utime, double span_s = 0.0,
                                     int64_t* resume = nullptr);

/// Logs "progress N% (t s)" each time another tenth of a run is played.
class ProgressLog {
 public:
  explicit ProgressLog(double span_s) : span_s_(span_s) {}
  void update(double played_s);

 private:
  double span_s_;
  int last_decile_{0};
};

/// Stays alive `seconds` after the last message (or until a stop signal), so
/// consumers can drain their queues before the driver's exit ends a run.
void linger(const Process& process, double seconds);

/// Encodes an LCM message and writes it at its own utime.
template <typename Msg>
void emit(EventSink& sink, const std::string& channel, const Msg& msg) {
  std::vector<uint8_t> buffer(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
  sink.write(channel, msg.utime, buffer.data(), static_cast<int>(buffer.size()));
}

}  // namespace vimot

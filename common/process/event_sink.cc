#include "common/process/event_sink.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "common/time/utime.h"

namespace vimot {
namespace {

std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

LogFileTail scan_log_file(const std::string& path) {
  LogFileTail tail;
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return tail;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read '" + path + "'");
  tail.file_bytes = static_cast<int64_t>(std::filesystem::file_size(path));
  // An event: marker, event number, timestamp, channel length, data length
  // (big-endian), then the channel and the data.
  constexpr uint32_t kMarker = 0xEDA1DA01;
  constexpr int64_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;
  const auto be32 = [](const unsigned char* b) {
    return (uint32_t{b[0]} << 24) | (uint32_t{b[1]} << 16) | (uint32_t{b[2]} << 8) | uint32_t{b[3]};
  };
  int64_t pos = 0;
  unsigned char header[kHeaderBytes];
  while (pos + kHeaderBytes <= tail.file_bytes) {
    in.seekg(pos);
    if (!in.read(reinterpret_cast<char*>(header), kHeaderBytes)) break;
    const int64_t channel_bytes = static_cast<int32_t>(be32(header + 20));
    const int64_t data_bytes = static_cast<int32_t>(be32(header + 24));
    if (be32(header) != kMarker || channel_bytes <= 0 || data_bytes < 0) {
      ++pos;  // not an event here: look for the next marker
      continue;
    }
    const int64_t end = pos + kHeaderBytes + channel_bytes + data_bytes;
    if (end > tail.file_bytes) break;  // cut short by the end of the file
    ++tail.events;
    tail.complete_bytes = end;
    pos = end;
  }
  return tail;
}

namespace {

// Cuts a half-written last event; returns what was found.
LogFileTail prepare_append(const std::string& path) {
  const LogFileTail tail = scan_log_file(path);
  if (tail.complete_bytes < tail.file_bytes) {
    std::error_code error;
    std::filesystem::resize_file(path, static_cast<std::uintmax_t>(tail.complete_bytes), error);
    if (error) throw std::runtime_error("cannot cut the half-written end of '" + path + "': " + error.message());
  }
  return tail;
}

}  // namespace

LogFileSink::LogFileSink(const std::string& path, Mode mode, bool flush_each)
    : found_(mode == Mode::kAppend ? prepare_append(path) : LogFileTail{}),
      log_(path, mode == Mode::kAppend ? "a" : "w"),
      flush_each_(flush_each) {
  if (!log_.good()) throw std::runtime_error("cannot open '" + path + "' for writing");
}

void LogFileSink::write(const std::string& channel, int64_t utime, const void* data, int size) {
  lcm::LogEvent ev;
  ev.eventnum = 0;  // LCM's writer numbers the events itself
  ev.timestamp = utime;  // message time, not wall time: same input, same bytes
  ev.channel = channel;
  ev.datalen = size;
  ev.data = const_cast<void*>(data);
  if (log_.writeEvent(&ev) != 0 || (flush_each_ && std::fflush(log_.getFilePtr()) != 0)) {
    throw std::runtime_error("writing the log failed (disk full?)");
  }
}

LcmSink::LcmSink(Process& process, double speed, int64_t first_utime, double start_delay_s)
    : process_(process), speed_(speed), first_utime_(first_utime) {
  wall_start_ = std::chrono::steady_clock::now() + seconds(start_delay_s);
  next_heartbeat_ = std::chrono::steady_clock::now();
}

void LcmSink::write(const std::string& channel, int64_t utime, const void* data, int size) {
  if (speed_ > 0.0) std::this_thread::sleep_until(wall_start_ + seconds(utime_to_seconds(utime - first_utime_) / speed_));
  if (process_.lcm().publish(channel, data, static_cast<unsigned>(size)) != 0) {
    process_.report_error("publish on " + channel + " failed");
  } else {
    ++process_.counters().messages_out;
  }
  const auto now = std::chrono::steady_clock::now();
  if (now >= next_heartbeat_) {
    process_.publish_heartbeat();
    next_heartbeat_ = now + std::chrono::seconds(1);
  }
}

void add_sink_options(ArgParser& args) {
  args.add_option("speed", "FACTOR", "real-time factor when publishing; 0 = as fast as possible", "1");
  args.add_option("start-delay", "SECONDS", "wait before the first message (lets subscribers start)", "0");
  args.add_option("log", "FILE", "write an LCM log file instead of publishing (as fast as possible)");
  args.add_option("linger", "SECONDS", "stay alive this long after the last message (lets consumers drain their queues)",
                  "0");
}

void add_clock_file_option(ArgParser& args) {
  args.add_option("clock-file", "FILE",
                  "keep the run's schedule across restarts of this driver: a restart within the run skips\n"
                  "what fell due while it was down, as a real sensor (the file holds the wall-clock time the\n"
                  "run's first message was due; a fresh run writes it)");
}

std::unique_ptr<EventSink> make_sink(Process& process, int64_t first_utime, double span_s, int64_t* resume) {
  const ArgParser& args = process.args();
  const double speed = args.get_double("speed");
  if (speed < 0.0) throw ArgError(process.name() + ": --speed must be >= 0, got " + args.get("speed"));
  if (resume != nullptr) *resume = first_utime;
  const bool clock_file = resume != nullptr && args.given("clock-file");
  if (clock_file && (args.given("log") || speed == 0.0)) {
    throw ArgError(process.name() + ": --clock-file needs a paced run (--speed > 0, no --log)");
  }
  if (args.given("log")) return std::make_unique<LogFileSink>(args.get("log"));
  double start_delay_s = args.get_double("start-delay");
  if (clock_file) {
    const std::string path = args.get("clock-file");
    const int64_t now = wall_clock_utime();
    int64_t first_due = -1;
    std::ifstream(path) >> first_due;
    const double since_first_s = utime_to_seconds(now - first_due);
    if (first_due > 0 && since_first_s >= 0.0 && since_first_s < span_s / speed) {
      *resume = first_utime + seconds_to_utime(since_first_s * speed);
      start_delay_s = -since_first_s;  // the first start's schedule
      log_info("restarted ", since_first_s, " s into the run of ", path, ": going on from ",
               utime_to_seconds(*resume - first_utime), " s of data");
    } else {
      std::ofstream out(path, std::ios::trunc);
      out << now + seconds_to_utime(start_delay_s) << "\n";
      if (!out.good()) throw std::runtime_error(process.name() + ": cannot write --clock-file '" + path + "'");
    }
  }
  return std::make_unique<LcmSink>(process, speed, first_utime, start_delay_s);
}

void ProgressLog::update(double played_s) {
  const int decile = static_cast<int>(10.0 * played_s / std::max(span_s_, 1e-9));
  if (decile > last_decile_) {
    last_decile_ = decile;
    log_info("progress ", 10 * decile, "% (", played_s, " s)");
  }
}

void linger(const Process& process, double seconds_to_stay) {
  const auto end = std::chrono::steady_clock::now() + seconds(seconds_to_stay);
  while (!process.stop_requested() && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace vimot

#include "common/process/event_sink.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <thread>

#include "common/time/utime.h"

namespace vimot {
namespace {

std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

LogFileSink::LogFileSink(const std::string& path, bool flush_each) : log_(path, "w"), flush_each_(flush_each) {
  if (!log_.good()) throw std::runtime_error("cannot open '" + path + "' for writing");
}

void LogFileSink::write(const std::string& channel, int64_t utime, const void* data, int size) {
  lcm::LogEvent ev;
  ev.eventnum = eventnum_++;
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

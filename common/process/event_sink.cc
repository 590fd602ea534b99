#include "common/process/event_sink.h"

#include <thread>

#include "common/time/utime.h"

namespace vimot {
namespace {

std::chrono::steady_clock::duration seconds(double s) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(s));
}

}  // namespace

LogFileSink::LogFileSink(const std::string& path) : log_(path, "w") {
  if (!log_.good()) throw std::runtime_error("cannot open '" + path + "' for writing");
}

void LogFileSink::write(const std::string& channel, int64_t utime, const void* data, int size) {
  lcm::LogEvent ev;
  ev.eventnum = eventnum_++;
  ev.timestamp = utime;  // message time, not wall time: same input, same bytes
  ev.channel = channel;
  ev.datalen = size;
  ev.data = const_cast<void*>(data);
  if (log_.writeEvent(&ev) != 0) throw std::runtime_error("writing the log failed (disk full?)");
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

void linger(const Process& process, double seconds_to_stay) {
  const auto end = std::chrono::steady_clock::now() + seconds(seconds_to_stay);
  while (!process.stop_requested() && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

}  // namespace vimot

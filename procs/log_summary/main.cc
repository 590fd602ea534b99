// vimot-log-summary: what an LCM log holds — per channel the message type,
// count, rate, and whether every message decodes as that type. Rates use the
// messages' own utimes (every vimot message starts with it), so a log
// recorded at 10x real time still shows sensor rates. The speed it was
// recorded at is the ratio of message time to log (wall-clock) time, which
// scripts/replay.sh needs to play it back at a chosen speed.
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>

#include <lcm/lcm-cpp.hpp>

#include "common/process/arg_parser.h"
#include "common/process/lcm_type_registry.h"
#include "common/process/process.h"
#include "common/time/utime.h"

namespace {

struct ChannelStats {
  std::set<std::string> types;
  int64_t count{0};
  int64_t bytes{0};
  int64_t undecodable{0};
  int64_t first_utime{0};
  int64_t last_utime{0};
  int64_t first_event_time{0};
  int64_t last_event_time{0};
  int64_t max_gap{0};       // longest log-time silence between two messages, µs
  int64_t max_gap_end{0};   // log time of the message that ended it
};

// Message time per log time on the busiest channel whose utime is sensor
// time (a vimot type other than heartbeat_t, whose utime is wall clock):
// 1 for vimot-sim --log, the real-time factor for lcm-logger's wall-clock
// event times; 0 if no channel spans any time.
double recorded_speed(const std::map<std::string, ChannelStats>& channels) {
  const ChannelStats* best = nullptr;
  for (const auto& [name, s] : channels) {
    const bool sensor_time = s.types.size() == 1 && s.types.count("(not a vimot type)") == 0 &&
                             s.types.count("vimot.heartbeat_t") == 0;
    if (sensor_time && s.count > 1 && (best == nullptr || s.count > best->count)) best = &s;
  }
  if (best == nullptr || best->last_event_time <= best->first_event_time) return 0.0;
  return static_cast<double>(best->last_utime - best->first_utime) /
         static_cast<double>(best->last_event_time - best->first_event_time);
}

int run(int argc, const char* const* argv) {
  vimot::ArgParser args("vimot-log-summary",
                        "Summarises an LCM log: channels, vimot message types, counts, rates, and decode\n"
                        "failures, and the speed it was recorded at (message time per log time).\n"
                        "Exits 2 if any vimot message fails to decode.");
  args.set_positional("LOG", "LCM log file (as written by lcm-logger or vimot-sim --log)", 1, 1);
  args.add_flag("speed", "print only the recorded speed (e.g. 2 for a run at twice real time; 0: unknown)");
  args.add_flag("gaps",
                "add each channel's longest silence in log time (s; lcm-logger: wall clock) and when it\n"
                "ended (s after the log's first message): how long a restarted process was away");
  if (!args.parse(argc, argv)) return 0;
  const std::string path = args.positionals()[0];

  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot open LCM log '" + path + "'");

  std::map<std::string, ChannelStats> channels;
  int64_t total = 0;
  int64_t undecodable = 0;
  int64_t log_start = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ChannelStats& s = channels[ev->channel];
    const vimot::LcmTypeInfo* type = vimot::find_lcm_type(ev->data, ev->datalen);
    if (type == nullptr) {
      s.types.insert("(not a vimot type)");
    } else {
      s.types.insert(type->name);
      if (!type->decodes(ev->data, ev->datalen)) {
        ++s.undecodable;
        ++undecodable;
      }
    }
    // Messages of other packages have no known utime: use the log's clock.
    const int64_t utime = type != nullptr && ev->datalen >= 16 ? vimot::vimot_message_utime(ev->data, ev->datalen) : ev->timestamp;
    if (s.count == 0) {
      s.first_utime = utime;
      s.first_event_time = ev->timestamp;
    }
    if (s.count > 0 && ev->timestamp - s.last_event_time > s.max_gap) {
      s.max_gap = ev->timestamp - s.last_event_time;
      s.max_gap_end = ev->timestamp;
    }
    s.last_utime = utime;
    s.last_event_time = ev->timestamp;
    if (total == 0) log_start = ev->timestamp;
    ++s.count;
    s.bytes += ev->datalen;
    ++total;
  }

  const double speed = recorded_speed(channels);
  if (args.given("speed")) {
    std::cout << std::setprecision(4) << speed << "\n";
    return undecodable > 0 ? 2 : 0;
  }
  std::cout << "log: " << path << "  (" << total << " messages, " << channels.size() << " channels)\n";
  std::cout << std::left << std::setw(24) << "channel" << std::setw(28) << "type" << std::right << std::setw(10)
            << "messages" << std::setw(10) << "rate Hz" << std::setw(12) << "kB" << std::setw(12) << "undecodable";
  const bool gaps = args.given("gaps");
  if (gaps) std::cout << std::setw(12) << "max gap s" << std::setw(10) << "ended s";
  std::cout << "\n";
  for (const auto& [name, s] : channels) {
    std::string type;
    for (const auto& t : s.types) type += (type.empty() ? "" : ",") + t;
    const double span = (s.last_utime - s.first_utime) * 1e-6;
    const double rate = s.count > 1 && span > 0 ? (s.count - 1) / span : 0.0;
    std::cout << std::left << std::setw(24) << name << std::setw(28) << type << std::right << std::setw(10) << s.count
              << std::setw(10) << std::fixed << std::setprecision(1) << rate << std::setw(12) << s.bytes / 1024
              << std::setw(12) << s.undecodable;
    if (gaps) {
      std::cout << std::setw(12) << std::setprecision(3) << vimot::utime_to_seconds(s.max_gap) << std::setw(10);
      // One message has no gap to have ended.
      if (s.count > 1) {
        std::cout << std::setprecision(1) << vimot::utime_to_seconds(s.max_gap_end - log_start);
      } else {
        std::cout << "-";
      }
    }
    std::cout << "\n";
  }
  std::cout << "recorded at " << std::setprecision(2) << speed
            << "x real time (message time per log time; vimot-sim --log: 1)\n";
  return undecodable > 0 ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

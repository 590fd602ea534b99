// vimot-log-summary: what an LCM log holds — per channel the message type,
// count, rate, and whether every message decodes as that type. Rates use the
// messages' own utimes (every vimot message starts with it), so a log
// recorded at 10x real time still shows sensor rates.
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>

#include <lcm/lcm-cpp.hpp>

#include "common/process/arg_parser.h"
#include "common/process/lcm_type_registry.h"
#include "common/process/process.h"

namespace {

// The utime field that follows the 8-byte fingerprint, big-endian.
int64_t message_utime(const void* data) {
  const auto* b = static_cast<const uint8_t*>(data) + 8;
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
  return static_cast<int64_t>(v);
}

struct ChannelStats {
  std::set<std::string> types;
  int64_t count{0};
  int64_t bytes{0};
  int64_t undecodable{0};
  int64_t first_utime{0};
  int64_t last_utime{0};
};

int run(int argc, const char* const* argv) {
  vimot::ArgParser args("vimot-log-summary",
                        "Summarises an LCM log: channels, vimot message types, counts, rates, and decode\n"
                        "failures. Exits 2 if any vimot message fails to decode.");
  args.set_positional("LOG", "LCM log file (as written by lcm-logger or vimot-sim --log)", 1, 1);
  if (!args.parse(argc, argv)) return 0;
  const std::string path = args.positionals()[0];

  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot open LCM log '" + path + "'");

  std::map<std::string, ChannelStats> channels;
  int64_t total = 0;
  int64_t undecodable = 0;
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
    const int64_t utime = type != nullptr && ev->datalen >= 16 ? message_utime(ev->data) : ev->timestamp;
    if (s.count == 0) s.first_utime = utime;
    s.last_utime = utime;
    ++s.count;
    s.bytes += ev->datalen;
    ++total;
  }

  std::cout << "log: " << path << "  (" << total << " messages, " << channels.size() << " channels)\n";
  std::cout << std::left << std::setw(24) << "channel" << std::setw(28) << "type" << std::right << std::setw(10)
            << "messages" << std::setw(10) << "rate Hz" << std::setw(12) << "kB" << std::setw(12) << "undecodable"
            << "\n";
  for (const auto& [name, s] : channels) {
    std::string type;
    for (const auto& t : s.types) type += (type.empty() ? "" : ",") + t;
    const double span = (s.last_utime - s.first_utime) * 1e-6;
    const double rate = s.count > 1 && span > 0 ? (s.count - 1) / span : 0.0;
    std::cout << std::left << std::setw(24) << name << std::setw(28) << type << std::right << std::setw(10) << s.count
              << std::setw(10) << std::fixed << std::setprecision(1) << rate << std::setw(12) << s.bytes / 1024
              << std::setw(12) << s.undecodable << "\n";
  }
  return undecodable > 0 ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

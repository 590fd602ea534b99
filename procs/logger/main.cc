// vimot-logger: writes every LCM message to an LCM event log (readable by
// lcm-logplayer, lcm-spy, vimot-log-summary), like lcm-logger but without
// losing messages silently: its queue holds --queue messages while the disk
// or the CPU is slow (lcm-logger has LCM's 30), its heartbeat counts what it
// logged per channel ("in <channel>"), and when stopped it goes on logging
// until the network is quiet (--drain, --drain-quiet), so the output of
// processes that drain their own input at the stop is logged too; anything
// left unlogged is counted as lost per channel (common/process/process.h).
// Event times are LCM's receive times (wall clock), as lcm-logger's.
#include "common/process/event_sink.h"
#include "common/process/process.h"

int main(int argc, char** argv) {
  return vimot::run_process_main([&] {
    vimot::Process process("vimot-logger",
                           "Logs every LCM message (channels matching --channels but not --exclude) to an LCM event log, counting\n"
                           "per channel what it logged in its heartbeat and \"stopping:\" line. Stop it with\n"
                           "SIGINT or SIGTERM; with --drain it first logs until the network has been quiet for\n"
                           "--drain-quiet seconds.");
    process.args().add_option("log", "FILE", "LCM log file to write (replaced if it exists; required)");
    process.args().add_option("channels", "REGEX", "channels to log (LCM regex, the whole name)", ".*");
    process.args().add_option("exclude", "REGEX",
                              "channels not to log, of those --channels selects (POSIX extended regex, the whole "
                              "name; e.g. 'PMD_.*|CAM_.*'); not counted",
                              "");
    // ≈ 100 s of the demo's traffic at 2x real time (≈ 1000 messages/s).
    process.args().add_option("queue", "MESSAGES", "messages held while the logger is busy; more are lost",
                              "100000");
    if (!process.init(argc, argv)) return 0;
    if (!process.args().given("log")) throw vimot::ArgError("vimot-logger: --log FILE is required (see --help)");
    const long long queue = process.args().get_int("queue");
    if (queue < 1 || queue > 100000000) {
      throw vimot::ArgError("vimot-logger: --queue must be 1 to 1e8 messages, got " + process.args().get("queue"));
    }
    vimot::LogFileSink sink(process.args().get("log"));
    process.subscribe_raw(
        process.args().get("channels"),
        [&sink](const std::string& channel, int64_t recv_utime, const void* data, int size) {
          sink.write(channel, recv_utime, data, size);
        },
        static_cast<int>(queue), process.args().get("exclude"));
    const std::string exclude = process.args().get("exclude");
    vimot::log_info("logging ", process.args().get("channels"), exclude.empty() ? "" : " but " + exclude, " to ",
                    process.args().get("log"));
    return process.run();
  });
}

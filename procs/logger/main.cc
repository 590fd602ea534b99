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
    process.args().add_option("log", "FILE", "LCM log file to write (replaced if it exists, unless --append; required)");
    process.args().add_flag("append",
                            "go on with FILE if it exists (a respawned logger keeps the run's record; a "
                            "half-written last event, its writer killed, is cut first)");
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
    const std::string path = process.args().get("log");
    const bool append = process.args().given("append");
    // Flushed per event: a respawned estimator catches up from this file
    // (--catch-up-log) while the run goes on.
    vimot::LogFileSink sink(path, append ? vimot::LogFileSink::Mode::kAppend : vimot::LogFileSink::Mode::kReplace,
                            /*flush_each=*/true);
    if (append && sink.found().file_bytes > 0) {
      const vimot::LogFileTail& found = sink.found();
      vimot::log_warn("appending to ", path, " (", found.events, " events already there",
                      found.complete_bytes < found.file_bytes
                          ? ", a half-written last event of " + std::to_string(found.file_bytes - found.complete_bytes) +
                                " bytes cut"
                          : std::string(),
                      "); what was published while no logger ran is not in it");
    }
    process.subscribe_raw(
        process.args().get("channels"),
        [&sink](const std::string& channel, int64_t recv_utime, const void* data, int size) {
          sink.write(channel, recv_utime, data, size);
        },
        static_cast<int>(queue), process.args().get("exclude"));
    const std::string exclude = process.args().get("exclude");
    vimot::log_info("logging ", process.args().get("channels"), exclude.empty() ? "" : " but " + exclude, " to ", path);
    return process.run();
  });
}

#pragma once
// The scaffold every vimot process stands on (pronto/libbot2 shape):
//   parse arguments -> load and validate config -> build handlers ->
//   subscribe -> loop on handle() until SIGINT/SIGTERM.
// It owns the LCM handle, the 1 Hz HEARTBEAT (counters: messages in/out,
// decode errors, dropped, errors) and the typed subscribe/publish wrappers
// that turn a malformed message or a throwing handler into a counted,
// logged error instead of a crash. The algorithm never sees this class.
//
// Common options: --lcm-url URL (default: $LCM_DEFAULT_URL, else LCM's
// default), --config FILE, --log-level LEVEL, --drain SECONDS,
// --drain-quiet SECONDS, --help.
//
// Stopping (SIGINT/SIGTERM) never loses input silently: with --drain S the
// input already queued is still handled, for at most S seconds and until
// the network has been quiet for --drain-quiet; what is still queued then
// is counted, unhandled, as lost on its channel ("lost <channel>"), so per
// channel: what a source that stopped first published = "in" + "lost" +
// what the network lost (docs/robustness.md).

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "common/config/config.h"
#include "common/process/arg_parser.h"
#include "common/process/lcm_type_registry.h"
#include "common/process/logger.h"

namespace vimot {

struct ProcessCounters {
  std::atomic<int64_t> messages_in{0};
  std::atomic<int64_t> messages_out{0};
  std::atomic<int64_t> decode_errors{0};
  std::atomic<int64_t> dropped{0};
  std::atomic<int64_t> errors{0};
  std::atomic<int64_t> lost{0};  // input that never arrived (utime gaps), in the heartbeat's `dropped`
};

class Process {
 public:
  /// `config_required`: --config must be given (a process with no sensible
  /// defaults); otherwise an absent --config gives an empty Config.
  Process(std::string name, std::string summary, bool config_required = false);
  ~Process();
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;

  /// Declare process-specific options here before init().
  ArgParser& args() { return args_; }

  /// Parses arguments, loads the config, opens LCM, installs the signal
  /// handlers. Returns false when the process should exit 0 (--help).
  /// Throws ArgError / ConfigError / std::runtime_error on bad input.
  bool init(int argc, const char* const* argv);

  const std::string& name() const { return name_; }
  const Config& config() const { return config_; }
  lcm::LCM& lcm() { return *lcm_; }
  ProcessCounters& counters() { return counters_; }

  /// A channel name from config key `channels.<role>`, `fallback` if absent.
  std::string channel(const std::string& role, const std::string& fallback) const;

  /// Subscribes with decoding done here (decode_untrusted: lengths checked
  /// before anything is allocated), so a malformed message is counted as a
  /// decode error and logged (rate-limited), never a crash.
  /// `queue_capacity`: messages LCM holds for this channel while the handler
  /// thread is busy; LCM silently drops what comes beyond (0: LCM's
  /// default, 30 — 0.15 s of a 200 Hz stream).
  /// `on_left` (optional) sees each message still queued at the stop, which
  /// is counted lost unhandled: the node can count the gaps between those
  /// messages too (loss inside a backlog is otherwise invisible).
  template <typename Msg>
  void subscribe(const std::string& channel, std::function<void(const Msg&)> handler, int queue_capacity = 0,
                 std::function<void(const Msg&)> on_left = {});

  /// The undecoded bytes of every message on the channels matching
  /// `channel_regex` (LCM's regex), with LCM's receive time (wall clock, µs)
  /// and the message's channel: for a logger. Counted per channel as above.
  /// Channels whose whole name matches `exclude_regex` (POSIX extended, as
  /// LCM's; empty: none) are skipped and not counted: LCM's regex cannot
  /// say "all but these". Throws ArgError on a malformed `exclude_regex`.
  using RawHandler = std::function<void(const std::string& channel, int64_t recv_utime, const void* data, int size)>;
  void subscribe_raw(const std::string& channel_regex, RawHandler handler, int queue_capacity = 0,
                     const std::string& exclude_regex = "");

  template <typename Msg>
  void publish(const std::string& channel, const Msg& msg) {
    if (lcm_->publish(channel, &msg) == 0) {
      ++counters_.messages_out;
      count_published(channel);
    } else {
      report_error("publish on " + channel + " failed");
    }
  }

  /// Logs and counts an error; the last one is carried by the heartbeat.
  void report_error(const std::string& what);
  /// Counts dropped input (late, duplicate, out-of-order) with a reason.
  void report_dropped(const std::string& why);
  /// Counts `count` input messages of `stream` that never arrived (a gap in
  /// its utime against its expected rate); per stream in the heartbeat's
  /// counters as "lost <stream>".
  void report_lost(int64_t count, const std::string& why, const std::string& stream = "");

  /// Sets a process-specific cumulative counter carried by the heartbeat
  /// (counter_names / counter_values, in first-set order) and the log line
  /// at exit. Call from the thread that publishes the heartbeat. The
  /// scaffold adds "in <channel>" (messages received per subscribed
  /// channel), "lost <stream>" (report_lost) and "out <channel>"
  /// (published), so what a source published can be checked against what
  /// arrived and what was said lost (scripts/demo_input_report.sh).
  void set_counter(const std::string& name, int64_t value);

  /// Handles LCM until stop() or a signal; sends a heartbeat every second.
  /// `idle` runs after each handled batch or timeout (e.g. deferred work).
  /// Then drains the input (--drain, above), logs the "stopping:" counts
  /// and sends a last heartbeat with them.
  int run(const std::function<void()>& idle = {});
  /// In `idle`: the wait before it timed out, so no input is pending (a
  /// quiet network, not a backlog left by a long handler on a busy CPU).
  bool idle_after_timeout() const { return idle_after_timeout_; }
  void stop() { stop_requested_ = true; }
  bool stop_requested() const;

  /// Publishes one heartbeat now (also called by run() at 1 Hz).
  void publish_heartbeat();

 private:
  struct RawSubscription;
  void handle_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel, RawSubscription* sub);
  /// After the stop: handles queued input (up to --drain), then counts what
  /// is left as lost.
  void drain(const std::function<void()>& idle);
  void maybe_publish_heartbeat();

  std::string name_;
  bool config_required_{false};
  ArgParser args_;
  Config config_;
  std::unique_ptr<lcm::LCM> lcm_;
  ProcessCounters counters_;
  std::string last_error_;
  std::vector<std::pair<std::string, int64_t>> extra_counters_;
  std::atomic<bool> stop_requested_{false};
  bool idle_after_timeout_{false};
  std::chrono::steady_clock::time_point next_heartbeat_{};

  // While counting what is left at the stop (drain()): messages are
  // counted per channel, not handled.
  bool counting_left_{false};
  std::vector<std::pair<std::string, int64_t>> left_by_channel_;

  // Subscriptions keep their closures alive for the LCM callbacks.
  // `decode_and_call` returns false for a message that does not decode;
  // `decode_left` (may be empty) takes a message left at the stop.
  using DecodeAndCall = std::function<bool(const lcm::ReceiveBuffer*, const std::string&)>;
  struct RawSubscription {
    Process* owner;
    DecodeAndCall decode_and_call;
    DecodeAndCall decode_left;
    std::optional<std::regex> exclude;
  };
  /// `literal`: `channel` is one channel, counted ("in <channel>") from 0;
  /// else a regex, whose channels are counted once seen.
  void add_subscription(const std::string& channel, bool literal, DecodeAndCall decode_and_call, int queue_capacity,
                        const std::string& exclude_regex = "", DecodeAndCall decode_left = {});
  void update_stream_counters();
  void count_published(const std::string& channel);
  std::vector<std::pair<std::string, int64_t>> in_by_channel_;
  std::vector<std::pair<std::string, int64_t>> lost_by_stream_;
  std::vector<std::pair<std::string, int64_t>> out_by_channel_;
  std::vector<std::unique_ptr<RawSubscription>> subscriptions_;
};

template <typename Msg>
void Process::subscribe(const std::string& channel, std::function<void(const Msg&)> handler, int queue_capacity,
                        std::function<void(const Msg&)> on_left) {
  const auto decoding = [](std::function<void(const Msg&)> call) -> DecodeAndCall {
    if (!call) return {};
    return [call = std::move(call)](const lcm::ReceiveBuffer* rbuf, const std::string&) {
      Msg msg;
      if (!decode_untrusted(rbuf->data, static_cast<int>(rbuf->data_size), &msg)) return false;
      call(msg);  // exceptions here are the handler's: counted as errors
      return true;
    };
  };
  add_subscription(channel, true, decoding(std::move(handler)), queue_capacity, "", decoding(std::move(on_left)));
}

/// Runs a process main, turning any escaping exception into a one-line error
/// and exit code 1 (bad arguments and configs are the common case).
int run_process_main(const std::function<int()>& body);

}  // namespace vimot

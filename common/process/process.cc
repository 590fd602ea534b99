#include "common/process/process.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdlib>
#include <iostream>
#include <regex>

#include "common/time/utime.h"
#include "vimot/heartbeat_t.hpp"

namespace vimot {

namespace {
std::atomic<bool> g_signal_received{false};

void on_signal(int) { g_signal_received = true; }

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
}  // namespace

Process::Process(std::string name, std::string summary, bool config_required)
    : name_(std::move(name)), config_required_(config_required), args_(name_, std::move(summary)) {
  args_.add_option("lcm-url", "URL", "LCM provider URL (default: $LCM_DEFAULT_URL, else LCM's default)");
  args_.add_option("config", "FILE", config_required ? "YAML configuration (required)" : "YAML configuration");
  args_.add_option("log-level", "LEVEL", "debug, info, warn or error", "info");
  args_.add_option("drain", "SECONDS",
                   "when stopped, go on handling the input already queued for at most this long; what is "
                   "left is counted as lost per channel",
                   "0");
  args_.add_option("drain-quiet", "SECONDS", "with --drain: stop draining once no input came for this long", "0.5");
}

Process::~Process() = default;

bool Process::init(int argc, const char* const* argv) {
  if (!args_.parse(argc, argv)) return false;
  set_log_name(name_);
  set_log_level(parse_log_level(args_.get("log-level")));
  if (args_.given("config")) {
    config_ = Config::load_file(args_.get("config"));
  } else if (config_required_) {
    throw ArgError(name_ + ": --config FILE is required (see --help)");
  }
  for (const char* key : {"drain", "drain-quiet"}) {
    if (!(args_.get_double(key) >= 0.0)) {
      throw ArgError(name_ + ": --" + key + " must be >= 0 seconds, got '" + args_.get(key) + "'");
    }
  }
  const std::string url = args_.get("lcm-url");
  lcm_ = std::make_unique<lcm::LCM>(url);
  if (!lcm_->good()) {
    throw std::runtime_error(name_ + ": cannot open LCM" + (url.empty() ? std::string() : " at '" + url + "'"));
  }
  install_signal_handlers();
  log_info("started (pid ", getpid(), ")");
  return true;
}

std::string Process::channel(const std::string& role, const std::string& fallback) const {
  return config_.get_or<std::string>("channels." + role, fallback);
}

namespace {
// Adds `n` to the count of `key` (kept in first-seen order).
void add_count(std::vector<std::pair<std::string, int64_t>>* counts, const std::string& key, int64_t n) {
  auto it = std::find_if(counts->begin(), counts->end(), [&](const auto& kc) { return kc.first == key; });
  if (it == counts->end()) it = counts->insert(counts->end(), {key, 0});
  it->second += n;
}
}  // namespace

void Process::add_subscription(const std::string& channel, bool literal, DecodeAndCall decode_and_call,
                               int queue_capacity, const std::string& exclude_regex, DecodeAndCall decode_left) {
  auto sub = std::make_unique<RawSubscription>();
  sub->owner = this;
  sub->decode_and_call = std::move(decode_and_call);
  sub->decode_left = std::move(decode_left);
  if (!exclude_regex.empty()) {
    try {
      sub->exclude.emplace(exclude_regex, std::regex::extended | std::regex::nosubs);
    } catch (const std::regex_error& e) {
      throw ArgError(name_ + ": bad channel regex to exclude '" + exclude_regex + "': " + e.what());
    }
  }
  lcm::Subscription* lcm_sub = lcm_->subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string& chan, RawSubscription* s) {
        s->owner->handle_raw(rbuf, chan, s);
      },
      sub.get());
  subscriptions_.push_back(std::move(sub));
  if (literal) add_count(&in_by_channel_, channel, 0);
  if (queue_capacity > 0 && lcm_sub != nullptr) lcm_sub->setQueueCapacity(queue_capacity);
}

void Process::subscribe_raw(const std::string& channel_regex, RawHandler handler, int queue_capacity,
                            const std::string& exclude_regex) {
  add_subscription(
      channel_regex, false,
      [handler = std::move(handler)](const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
        handler(channel, rbuf->recv_utime, rbuf->data, static_cast<int>(rbuf->data_size));
        return true;
      },
      queue_capacity, exclude_regex);
}

void Process::handle_raw(const lcm::ReceiveBuffer* rbuf, const std::string& channel, RawSubscription* sub) {
  if (sub->exclude && std::regex_match(channel, *sub->exclude)) return;
  if (counting_left_) {
    add_count(&left_by_channel_, channel, 1);
    if (sub->decode_left) {
      try {
        sub->decode_left(rbuf, channel);  // one that does not decode is counted above all the same
      } catch (const std::exception& e) {
        report_error("counting what is left on " + channel + ": " + e.what());
      }
    }
    return;
  }
  add_count(&in_by_channel_, channel, 1);
  ++counters_.messages_in;
  bool decoded = false;
  try {
    decoded = sub->decode_and_call(rbuf, channel);
  } catch (const std::exception& e) {
    report_error("handling " + channel + ": " + e.what());
    return;
  }
  if (!decoded) {
    ++counters_.decode_errors;
    log_warn("cannot decode a ", rbuf->data_size, "-byte message on ", channel,
             " (wrong type, corrupt, or a length longer than the message); dropped");
  }
}

void Process::report_error(const std::string& what) {
  ++counters_.errors;
  last_error_ = what;
  log_error(what);
}

void Process::report_dropped(const std::string& why) {
  ++counters_.dropped;
  log_warn("dropped: ", why);
}

void Process::set_counter(const std::string& name, int64_t value) {
  for (auto& [n, v] : extra_counters_) {
    if (n == name) {
      v = value;
      return;
    }
  }
  extra_counters_.emplace_back(name, value);
}

void Process::report_lost(int64_t count, const std::string& why, const std::string& stream) {
  counters_.lost += count;
  if (!stream.empty()) add_count(&lost_by_stream_, stream, count);
  log_warn("lost: ", why);
}

void Process::count_published(const std::string& channel) { add_count(&out_by_channel_, channel, 1); }

void Process::update_stream_counters() {
  for (const auto& [channel, n] : in_by_channel_) set_counter("in " + channel, n);
  for (const auto& [stream, n] : lost_by_stream_) set_counter("lost " + stream, n);
  for (const auto& [channel, n] : out_by_channel_) set_counter("out " + channel, n);
}

bool Process::stop_requested() const { return stop_requested_ || g_signal_received; }

void Process::publish_heartbeat() {
  heartbeat_t hb;
  hb.utime = wall_clock_utime();  // monitoring only, never used for estimation
  hb.name = name_;
  hb.pid = static_cast<int32_t>(getpid());
  hb.messages_in = counters_.messages_in;
  hb.messages_out = counters_.messages_out;
  hb.decode_errors = counters_.decode_errors;
  hb.dropped = counters_.dropped + counters_.lost;
  hb.errors = counters_.errors;
  // Anything not used as it came (dropped, lost, undecodable) or an error
  // (a reset of the estimate included) makes the output suspect.
  const bool degraded =
      counters_.errors > 0 || counters_.dropped > 0 || counters_.lost > 0 || counters_.decode_errors > 0;
  hb.status = degraded ? "degraded" : "ok";
  hb.last_error = last_error_;
  update_stream_counters();
  hb.num_counters = static_cast<int32_t>(extra_counters_.size());
  for (const auto& [n, v] : extra_counters_) {
    hb.counter_names.push_back(n);
    hb.counter_values.push_back(v);
  }
  lcm_->publish(config_.get_or<std::string>("channels.heartbeat", "HEARTBEAT"), &hb);
}

void Process::maybe_publish_heartbeat() {
  if (std::chrono::steady_clock::now() < next_heartbeat_) return;
  publish_heartbeat();
  flush_suppressed_logs();
  next_heartbeat_ += std::chrono::seconds(1);
}

int Process::run(const std::function<void()>& idle) {
  next_heartbeat_ = std::chrono::steady_clock::now();
  while (!stop_requested()) {
    const int status = lcm_->handleTimeout(100);
    if (status < 0) {
      if (stop_requested()) break;  // a stop signal interrupted the wait
      report_error("LCM handle failed");
      return 1;
    }
    idle_after_timeout_ = status == 0;
    if (idle) idle();
    maybe_publish_heartbeat();
  }
  drain(idle);
  flush_suppressed_logs();
  update_stream_counters();
  std::string per_stream;
  for (const auto& [n, v] : extra_counters_) per_stream += ", " + n + " " + std::to_string(v);
  log_info("stopping: in ", counters_.messages_in.load(), ", out ", counters_.messages_out.load(),
           ", decode errors ", counters_.decode_errors.load(), ", dropped ", counters_.dropped.load(), ", lost ", counters_.lost.load(),
           ", errors ", counters_.errors.load(), per_stream, ", cpu ",
           static_cast<double>(std::clock()) / CLOCKS_PER_SEC, " s");
  publish_heartbeat();  // the final counts, for a monitor that missed the log
  return 0;
}

void Process::drain(const std::function<void()>& idle) {
  using Clock = std::chrono::steady_clock;
  const auto ms = [](double s) { return static_cast<int64_t>(s * 1000.0); };
  const int64_t quiet_ms = std::max<int64_t>(1, ms(args_.get_double("drain-quiet")));
  const Clock::time_point deadline = Clock::now() + std::chrono::milliseconds(ms(args_.get_double("drain")));
  // No heartbeat while draining: a logger that drains until the network is
  // quiet would otherwise keep itself busy with its own. A second signal
  // ends the drain (the user insists).
  g_signal_received = false;
  while (!g_signal_received) {
    const int64_t left_ms = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left_ms <= 0) break;
    const int status = lcm_->handleTimeout(static_cast<int>(std::min(quiet_ms, left_ms)));
    if (status == 0) break;  // quiet: the backlog is done
    if (status < 0) {
      if (!g_signal_received) report_error("LCM handle failed while draining");
      break;
    }
    idle_after_timeout_ = false;
    if (idle) idle();
  }
  // What is still queued or in the socket is not handled: lost. Short
  // waits: only LCM's receive thread still delivers it (LCM stamps a
  // message when that thread reads it, so time cannot tell a backlog from a
  // source still publishing: the count stops after kCountLimit, and a live
  // source's last messages then count as lost too).
  constexpr auto kCountLimit = std::chrono::seconds(1);
  const Clock::time_point count_end = Clock::now() + kCountLimit;
  counting_left_ = true;
  while (Clock::now() < count_end && lcm_->handleTimeout(50) > 0) {
  }
  counting_left_ = false;
  for (const auto& [channel, n] : left_by_channel_) {
    report_lost(n, std::to_string(n) + " message(s) on " + channel + " still queued when stopped", channel);
  }
}

int run_process_main(const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << std::endl;
    return 1;
  }
}

}  // namespace vimot

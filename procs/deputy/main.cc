// vimot-deputy: a libbot2 procman deputy. Obeys orders on PMD_ORDERS2 for
// its host name, runs the commands through the sheriff's ProcessRunner,
// publishes PMD_INFO2 once a second and after every change, command output
// on PMD_PRINTF, and answers PMD_DISCOVER. All logic is in DeputyNode; this
// file moves bytes. See docs/sheriff.md.

#include <chrono>
#include <cstdlib>
#include <exception>
#include <functional>
#include <string>
#include <vector>

#include "common/process/process.h"
#include "common/time/utime.h"
#include "procs/deputy/deputy_node.h"
#include "procs/sheriff/host_info.h"
#include "procs/sheriff/procman_lcm.h"

namespace {

using vimot::sheriff::FromLcm;
using vimot::sheriff::ToLcm;

// procman's types are not in vimot's layout registry (which
// Process::subscribe checks lengths against), so they are decoded here
// against their own layouts: a malformed message is counted and dropped,
// never a crash.
struct Subscription {
  vimot::Process* process;
  std::function<void(const void*, int)> decode_and_call;
};

template <typename Msg>
void Subscribe(vimot::Process& process, std::vector<std::unique_ptr<Subscription>>& subs,
               const std::string& channel, std::function<void(const Msg&)> handler) {
  auto sub = std::make_unique<Subscription>();
  sub->process = &process;
  sub->decode_and_call = [&process, channel, handler](const void* data, int size) {
    Msg msg;
    if (!vimot::sheriff::DecodeProcman(data, size, &msg)) {
      ++process.counters().decode_errors;
      return;
    }
    ++process.counters().messages_in;
    handler(msg);
  };
  process.lcm().subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer* rbuf, const std::string&, Subscription* s) {
        s->decode_and_call(rbuf->data, static_cast<int>(rbuf->data_size));
      },
      sub.get());
  subs.push_back(std::move(sub));
}

int run(int argc, const char* const* argv) {
  vimot::Process process(
      "deputy",
      "libbot2 procman deputy: runs the commands a sheriff (vimot-sheriff --lcm\n"
      "or bot-procman-sheriff) orders for this host on PMD_ORDERS2, reports\n"
      "them on PMD_INFO2 and their output on PMD_PRINTF. On SIGINT/SIGTERM it\n"
      "stops its commands (stop signal, SIGKILL after stop_time_allowed).");
  process.args().add_option("name", "HOST",
                            "the host name sheriffs address this deputy by (default: hostname)");
  if (!process.init(argc, argv)) return 0;

  vimot::deputy::DeputyOptions options;
  options.host =
      process.args().given("name") ? process.args().get("name") : vimot::sheriff::HostName();
  if (std::getenv("VIMOT_BIN") == nullptr) {
    if (const auto dir = vimot::sheriff::ExecutableDirectory()) {
      options.runner.environment["VIMOT_BIN"] = *dir;
    }
  }
  vimot::deputy::DeputyNode node(options, [&](const vimot::sheriff::DeputyOutput& out) {
    process.publish(vimot::sheriff::kPrintfChannel, ToLcm(out));
  });

  using Clock = std::chrono::steady_clock;
  auto next_info = Clock::now();
  const auto publish_info = [&] {
    process.publish(vimot::sheriff::kInfoChannel, ToLcm(node.Info(vimot::wall_clock_utime())));
    next_info = Clock::now() + std::chrono::seconds(1);
  };

  std::vector<std::unique_ptr<Subscription>> subs;
  Subscribe<bot_procman::orders2_t>(process, subs, vimot::sheriff::kOrdersChannel,
                                    [&](const bot_procman::orders2_t& msg) {
                                      if (node.OnOrders(FromLcm(msg), vimot::wall_clock_utime())) {
                                        publish_info();
                                      }
                                    });
  Subscribe<bot_procman::discovery_t>(process, subs, vimot::sheriff::kDiscoverChannel,
                                      [&](const bot_procman::discovery_t&) { publish_info(); });
  vimot::log_info("deputy '", node.host(), "' ready");

  const auto step = [&](std::chrono::milliseconds wait) {
    if (node.Poll(wait, vimot::wall_clock_utime()) || Clock::now() >= next_info) publish_info();
  };
  const int status = process.run([&] { step(std::chrono::milliseconds(0)); });

  // Stopped by a signal: stop the commands, keep reporting until they end.
  node.StopAll();
  while (!node.IsIdle()) {
    process.lcm().handleTimeout(0);
    step(std::chrono::milliseconds(50));
  }
  publish_info();
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

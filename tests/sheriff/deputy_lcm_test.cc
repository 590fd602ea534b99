// vimot-sheriff --lcm and vimot-deputy end to end over a private LCM URL
// (multicast with ttl=0: stays on this machine): our sheriff starts,
// restarts and stops a command on a deputy by procman's protocol, sees its
// state change and its output, and every message on the PMD_* channels is
// one of libbot2's types.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <atomic>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "procs/sheriff/procman_lcm.h"
#include "tests/sheriff/test_util.h"

using namespace vimot::sheriff;
using namespace vimot::sheriff::test;

namespace {

// A port no other test uses, so parallel ctest runs do not cross-talk.
constexpr char kUrl[] = "udpm://239.255.76.67:7694?ttl=0";

constexpr char kConfig[] = R"(
cmd "talker" {
  exec = "echo hello from talker; exec sleep 30";
  host = "vehicle";
  stop_signal = 15;
  stop_time_allowed = 2;
}
script "exercise" {
  start cmd "talker" wait "running";
  wait ms 1000;
  restart cmd "talker" wait "running";
  wait ms 1000;
  stop cmd "talker" wait "stopped";
}
)";

/// Every message seen on the PMD_* channels, raw.
struct Capture {
  std::mutex mutex;
  std::vector<std::pair<std::string, std::vector<uint8_t>>> messages;

  void Handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const auto* data = static_cast<const uint8_t*>(rbuf->data);
    std::lock_guard<std::mutex> lock(mutex);
    messages.emplace_back(channel, std::vector<uint8_t>(data, data + rbuf->data_size));
  }
};

/// Runs a shell command; its stdout (and stderr, if redirected) and exit
/// status, -1 when it did not exit normally.
std::pair<int, std::string> RunCommand(const std::string& command) {
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  char buffer[4096];
  std::size_t n = 0;
  while ((n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0) output.append(buffer, n);
  const int status = ::pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

template <typename Msg>
bool DecodesAs(const std::vector<uint8_t>& bytes, Msg* msg) {
  return msg->decode(bytes.data(), 0, static_cast<int>(bytes.size())) ==
         static_cast<int>(bytes.size());
}

}  // namespace

TEST_CASE("vimot-sheriff --lcm drives a vimot-deputy by procman's protocol") {
  TempDir dir;
  const std::string config = dir.path() + "/exercise.pmd";
  std::ofstream(config) << kConfig;

  lcm::LCM listener(kUrl);
  REQUIRE(listener.good());
  Capture capture;
  listener.subscribe("PMD_.*", &Capture::Handle, &capture);
  std::atomic<bool> listening{true};
  std::thread listen_thread([&] {
    while (listening) listener.handleTimeout(50);
  });

  // The deputy runs under our own ProcessRunner, which stops it at the end.
  Recorder deputy_log;
  ProcessRunner deputy({Command("deputy", std::string("'") + VIMOT_DEPUTY_BIN +
                                              "' --name vehicle --lcm-url '" + kUrl + "'")},
                       deputy_log.Options());
  deputy.Start("deputy");
  REQUIRE(PollUntil(&deputy, [&] { return deputy_log.HasOutput("deputy 'vehicle' ready"); }));

  // Hostile orders first: a header claiming 10^8 commands. The deputy must
  // drop them and go on serving.
  // fingerprint, utime, host "" and sheriff_name "" (length 1: the NUL), ncmds.
  std::vector<uint8_t> garbage;
  const auto put = [&](uint64_t v, int bytes) {
    for (int i = bytes - 1; i >= 0; --i) garbage.push_back(static_cast<uint8_t>(v >> (8 * i)));
  };
  put(static_cast<uint64_t>(bot_procman::orders2_t::getHash()), 8);
  put(0, 8);
  put(1, 4);
  put(0, 1);
  put(1, 4);
  put(0, 1);
  put(100'000'000, 4);
  listener.publish(kOrdersChannel, garbage.data(), static_cast<unsigned>(garbage.size()));

  const std::string command = std::string("'") + VIMOT_SHERIFF_BIN + "' --lcm --lcm-url '" +
                              kUrl + "' --duration 20 --script exercise '" + config + "' 2>&1";
  std::string output;
  std::atomic<bool> sheriff_done{false};
  // The sheriff runs in another thread while this one polls the deputy's runner.
  std::thread sheriff_thread([&] {
    const auto [status, text] = RunCommand(command);
    output = text + "\nEXIT " + std::to_string(status);
    sheriff_done = true;
  });
  const Clock::time_point end = Clock::now() + std::chrono::seconds(30);
  while (deputy.state("deputy").status == CommandStatus::kRunning && Clock::now() < end &&
         !sheriff_done) {
    deputy.Poll(milliseconds(50));
  }
  sheriff_thread.join();
  deputy.StopAll();
  REQUIRE(PollUntil(&deputy, [&] { return deputy.IsIdle(); }));
  listening = false;
  listen_thread.join();

  INFO(output);
  CHECK(output.find("\nEXIT 0") != std::string::npos);
  // Two runs, each with its own pid, then stopped.
  const std::regex running("vehicle:talker running \\(pid ([0-9]+)\\)");
  std::set<std::string> pids;
  for (auto it = std::sregex_iterator(output.begin(), output.end(), running);
       it != std::sregex_iterator(); ++it) {
    pids.insert((*it)[1]);
  }
  CHECK(pids.size() == 2);
  CHECK(output.find("vehicle:talker stopped") != std::string::npos);
  // The command's output, once per run, through PMD_PRINTF.
  std::size_t hellos = 0;
  for (std::size_t at = output.find("[vehicle:talker] hello from talker");
       at != std::string::npos; at = output.find("[vehicle:talker] hello from talker", at + 1)) {
    ++hellos;
  }
  CHECK(hellos == 2);

  // What went over the wire is procman's: each channel's messages carry
  // the fingerprint of its libbot2 type and decode as it.
  std::map<std::string, int> counts;
  int64_t last_runid = 0;
  bool saw_talker_output = false;
  for (const auto& [channel, bytes] : capture.messages) {
    if (bytes == garbage) continue;
    ++counts[channel];
    if (channel == kOrdersChannel) {
      bot_procman::orders2_t msg;
      REQUIRE(DecodesAs(bytes, &msg));
      CHECK(msg.host == "vehicle");
      REQUIRE(msg.ncmds == 1);
      CHECK(msg.cmds[0].cmd.command_name == "talker");
      CHECK(msg.cmds[0].desired_runid >= last_runid);
      last_runid = msg.cmds[0].desired_runid;
    } else if (channel == kInfoChannel) {
      bot_procman::info2_t msg;
      REQUIRE(DecodesAs(bytes, &msg));
      CHECK(msg.host == "vehicle");
    } else if (channel == kPrintfChannel) {
      bot_procman::printf_t msg;
      REQUIRE(DecodesAs(bytes, &msg));
      saw_talker_output |= msg.text == "hello from talker\n" && msg.sheriff_id == 1;
    } else if (channel == kDiscoverChannel) {
      bot_procman::discovery_t msg;
      REQUIRE(DecodesAs(bytes, &msg));
    } else {
      FAIL("unexpected channel " << channel);
    }
  }
  CHECK(last_runid == 2);  // one start, one restart
  CHECK(saw_talker_output);
  CHECK(counts[kOrdersChannel] > 0);
  CHECK(counts[kInfoChannel] > 0);
  CHECK(counts[kDiscoverChannel] == 1);
}

TEST_CASE("vimot-sheriff --lcm rejects what it cannot do before sending anything") {
  TempDir dir;
  const std::string config = dir.path() + "/exercise.pmd";
  std::ofstream(config) << kConfig;
  const std::string command = std::string("'") + VIMOT_SHERIFF_BIN + "' --lcm --lcm-url '" +
                              kUrl + "' --exit-when talker '" + config + "' 2>&1";
  const auto [status, output] = RunCommand(command);
  CHECK(status == 2);
  CHECK(output.find("--exit-when is not supported with --lcm") != std::string::npos);
  // An LCM option without --lcm is a mistake, not something to ignore.
  const auto [status2, output2] = RunCommand(std::string("'") + VIMOT_SHERIFF_BIN +
                                             "' --lcm-url '" + kUrl + "' '" + config + "' 2>&1");
  CHECK(status2 == 2);
  CHECK(output2.find("only apply with --lcm") != std::string::npos);
}


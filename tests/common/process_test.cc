// The process scaffold over a real in-memory LCM: typed messages reach the
// handler, garbage and throwing handlers are counted instead of crashing,
// and the heartbeat carries the counters.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>

#include "common/process/process.h"
#include "vimot/heartbeat_t.hpp"
#include "vimot/imu_t.hpp"

using vimot::Process;

namespace {
std::unique_ptr<Process> make_process(const std::vector<std::string>& extra = {}) {
  auto p = std::make_unique<Process>("test-proc", "A test process.");
  std::vector<const char*> argv{"test-proc", "--lcm-url", "memq://", "--log-level", "error"};
  for (const auto& a : extra) argv.push_back(a.c_str());
  REQUIRE(p->init(static_cast<int>(argv.size()), argv.data()));
  return p;
}
}  // namespace

TEST_CASE("typed subscription delivers decoded messages and counts them") {
  auto p = make_process();
  std::vector<int64_t> seen;
  p->subscribe<vimot::imu_t>("IMU", [&](const vimot::imu_t& m) { seen.push_back(m.utime); });
  vimot::imu_t m{};
  m.utime = 123;
  p->publish("IMU", m);
  m.utime = 456;
  p->publish("IMU", m);
  while (p->lcm().handleTimeout(10) > 0) {
  }
  CHECK(seen == std::vector<int64_t>{123, 456});
  CHECK(p->counters().messages_in == 2);
  CHECK(p->counters().messages_out == 2);
}

TEST_CASE("a malformed message and a throwing handler are counted, not fatal") {
  auto p = make_process();
  int calls = 0;
  p->subscribe<vimot::imu_t>("IMU", [&](const vimot::imu_t& m) {
    ++calls;
    if (m.utime < 0) throw std::runtime_error("negative time");
  });
  const char garbage[] = "definitely not an imu_t";
  p->lcm().publish("IMU", garbage, sizeof(garbage));
  vimot::imu_t bad{};
  bad.utime = -1;
  p->publish("IMU", bad);
  while (p->lcm().handleTimeout(10) > 0) {
  }
  CHECK(calls == 1);
  CHECK(p->counters().decode_errors == 1);
  CHECK(p->counters().errors == 1);
}

TEST_CASE("heartbeat carries name and counters") {
  auto p = make_process();
  vimot::heartbeat_t got{};
  bool received = false;
  p->subscribe<vimot::heartbeat_t>("HEARTBEAT", [&](const vimot::heartbeat_t& hb) {
    got = hb;
    received = true;
  });
  const auto beat = [&] {
    received = false;
    p->publish_heartbeat();
    while (p->lcm().handleTimeout(10) > 0) {
    }
    REQUIRE(received);
  };
  beat();
  CHECK(got.name == "test-proc");
  CHECK(got.status == "ok");
  p->report_dropped("test");
  p->set_counter("bytes_dropped", 5);
  p->set_counter("reconnects", 1);
  p->set_counter("bytes_dropped", 7);  // updated in place, order kept
  beat();
  CHECK(got.dropped == 1);
  CHECK(got.messages_out == 0);  // the heartbeat itself is not counted
  // Input not used as it came makes the output suspect (heartbeat_t.lcm).
  CHECK(got.status == "degraded");
  // The scaffold's own first: messages received per subscribed channel
  // (the first heartbeat), then the process's.
  CHECK(got.counter_names == std::vector<std::string>({"in HEARTBEAT", "bytes_dropped", "reconnects"}));
  CHECK(got.counter_values == std::vector<int64_t>({1, 7, 1}));
}

TEST_CASE("input lost on the way is counted with the dropped and degrades the status") {
  auto p = make_process();
  vimot::heartbeat_t got{};
  p->subscribe<vimot::heartbeat_t>("HEARTBEAT", [&](const vimot::heartbeat_t& hb) { got = hb; });
  p->report_lost(3, "3 IMU messages lost", "IMU");
  p->report_lost(1, "1 FEATURES message lost", "FEATURES");
  p->report_lost(2, "2 IMU messages lost", "IMU");
  p->publish_heartbeat();
  while (p->lcm().handleTimeout(10) > 0) {
  }
  CHECK(p->counters().lost == 6);
  CHECK(got.dropped == 6);
  CHECK(got.status == "degraded");
  // Per stream, in the order first lost.
  CHECK(got.counter_names == std::vector<std::string>({"in HEARTBEAT", "lost IMU", "lost FEATURES"}));
  CHECK(got.counter_values == std::vector<int64_t>({0, 5, 1}));
}

TEST_CASE("channels come from config; a missing required config is an error") {
  const std::string path = "process_test_config.yaml";
  std::ofstream(path) << "channels:\n  imu: IMU_ALT\n";
  auto p = make_process({"--config", path});
  CHECK(p->channel("imu", "IMU") == "IMU_ALT");
  CHECK(p->channel("features", "FEATURES") == "FEATURES");

  Process needs_config("needs-config", "x", true);
  const char* argv[] = {"needs-config", "--lcm-url", "memq://"};
  CHECK_THROWS_WITH(needs_config.init(3, argv), Catch::Contains("--config FILE is required"));
}

// Issue 12, item 6: input still queued when the process is stopped is either
// handled (--drain) or counted as lost on its channel, never forgotten, so
// what a source published = "in" + "lost" per channel.
TEST_CASE("input queued at the stop is drained with --drain, else counted as lost per channel") {
  const bool drain = GENERATE(false, true);
  auto p = make_process({"--drain", drain ? "5" : "0", "--drain-quiet", "0.1"});
  int handled = 0;
  p->subscribe<vimot::imu_t>("IMU", [&](const vimot::imu_t&) { ++handled; });
  vimot::imu_t m{};
  for (int i = 0; i < 100; ++i) {
    m.utime = i;
    p->publish("IMU", m);
  }
  // The last heartbeat, sent after the drain, carries the final counts.
  vimot::heartbeat_t got{};
  p->subscribe<vimot::heartbeat_t>("HEARTBEAT", [&](const vimot::heartbeat_t& hb) { got = hb; });
  p->stop();  // before anything was handled: all 100 are the backlog
  CHECK(p->run() == 0);
  while (p->lcm().handleTimeout(10) > 0) {
  }
  std::map<std::string, int64_t> counters;
  for (int i = 0; i < got.num_counters; ++i) counters[got.counter_names[i]] = got.counter_values[i];
  INFO("--drain " << (drain ? 5 : 0));
  CHECK(handled == (drain ? 100 : 0));
  CHECK(counters["in IMU"] == (drain ? 100 : 0));
  CHECK(counters.count("lost IMU") == (drain ? 0u : 1u));
  CHECK(counters["lost IMU"] == (drain ? 0 : 100));
  CHECK(got.dropped == (drain ? 0 : 100));
  CHECK(got.status == (drain ? "ok" : "degraded"));
}

TEST_CASE("a message left at the stop reaches the subscription's on_left, unhandled, in order") {
  auto p = make_process({"--drain", "0"});
  int handled = 0;
  std::vector<int64_t> left;
  p->subscribe<vimot::imu_t>(
      "IMU", [&](const vimot::imu_t&) { ++handled; }, 0, [&](const vimot::imu_t& m) { left.push_back(m.utime); });
  vimot::imu_t m{};
  for (const int64_t utime : {10, 20, 40, 50}) {
    m.utime = utime;
    p->publish("IMU", m);
  }
  p->stop();
  CHECK(p->run() == 0);
  CHECK(handled == 0);
  CHECK(left == std::vector<int64_t>{10, 20, 40, 50});
}

TEST_CASE("--drain and --drain-quiet must be non-negative seconds") {
  for (const char* bad : {"-1", "x"}) {
    Process p("test-proc", "x");
    const char* argv[] = {"test-proc", "--lcm-url", "memq://", "--drain", bad};
    CHECK_THROWS_WITH(p.init(5, argv), Catch::Contains("--drain"));
  }
}

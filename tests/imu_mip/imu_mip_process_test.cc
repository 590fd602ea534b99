// vimot-imu-mip as a process: the real binary against the simulated device
// on a pty (interface: tty), publishing into an LCM log (file:// provider,
// no network). The log must hold every intact sample, decoded, and a
// heartbeat whose counters account for the faults the device injected.
#include <catch2/catch.hpp>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <fstream>
#include <lcm/lcm-cpp.hpp>

#include "tests/imu_mip/simulated_mip_device.h"
#include "vimot/heartbeat_t.hpp"
#include "vimot/imu_t.hpp"

extern char** environ;

using vimot::mip::test::SimulatedMipDevice;

namespace {

void sleep_s(double s) { std::this_thread::sleep_for(std::chrono::duration<double>(s)); }

template <typename Pred>
bool wait_for(Pred done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done() && std::chrono::steady_clock::now() < end) sleep_s(0.01);
  return done();
}

int64_t counter(const vimot::heartbeat_t& hb, const std::string& name) {
  for (int i = 0; i < hb.num_counters; ++i) {
    if (hb.counter_names[static_cast<std::size_t>(i)] == name) return hb.counter_values[static_cast<std::size_t>(i)];
  }
  FAIL("heartbeat has no counter " << name);
  return -1;
}

}  // namespace

TEST_CASE("vimot-imu-mip publishes every intact sample and counts the faults in its heartbeat") {
  SimulatedMipDevice device(SimulatedMipDevice::Behaviour{});
  const std::string config_path = "imu_mip_process_test.yaml";
  const std::string log_path = "imu_mip_process_test.lcm";
  std::remove(log_path.c_str());
  std::ofstream(config_path) << "device:\n  port: " << device.slave_path()
                             << "\n  interface: tty\n  rate: 200\n  stream_timeout: 5\n"
                                "channels:\n  imu: IMU_TEST\n  heartbeat: HEARTBEAT_TEST\n";

  const std::string url = "file://" + log_path + "?mode=w";
  std::vector<std::string> args = {VIMOT_IMU_MIP_BIN, "--config", config_path, "--lcm-url", url, "--log-level",
                                   "error"};
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) == 0);

  REQUIRE(wait_for([&] { return device.commands().size() == 5; }, 10.0));
  device.stream(200);
  REQUIRE(wait_for([&] { return device.idle_to_send(); }, 10.0));
  sleep_s(2.5);  // a heartbeat after the last sample
  kill(pid, SIGTERM);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);

  const SimulatedMipDevice::Sent sent = device.sent();
  lcm::LogFile log(log_path, "r");
  REQUIRE(log.good());
  std::vector<vimot::imu_t> imu;
  vimot::heartbeat_t last_heartbeat{};
  int heartbeats = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    if (ev->channel == "IMU_TEST") {
      vimot::imu_t m;
      REQUIRE(m.decode(ev->data, 0, ev->datalen) == ev->datalen);
      imu.push_back(m);
    } else if (ev->channel == "HEARTBEAT_TEST") {
      REQUIRE(last_heartbeat.decode(ev->data, 0, ev->datalen) == ev->datalen);
      ++heartbeats;
    }
  }
  REQUIRE(imu.size() == sent.good.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    const auto expected = vimot::mip::test::test_sample(sent.good[i], 200.0);
    CHECK(imu[i].linear_acceleration[2] == Approx(expected.accel_g[2] * vimot::mip::kStandardGravity));
    CHECK(imu[i].angular_velocity[0] == Approx(expected.gyro[0]).margin(1e-9));
    if (i > 0) CHECK(imu[i].utime > imu[i - 1].utime);
  }
  REQUIRE(heartbeats >= 2);
  CHECK(last_heartbeat.name == "vimot-imu-mip");
  CHECK(last_heartbeat.messages_out >= static_cast<int64_t>(imu.size()));
  CHECK(counter(last_heartbeat, "bytes_dropped") == sent.dropped_bytes);
  CHECK(counter(last_heartbeat, "checksum_errors") >= sent.corrupted + sent.truncated);
  CHECK(counter(last_heartbeat, "packets_dropped") == last_heartbeat.dropped);
  CHECK(counter(last_heartbeat, "reconnects") == 0);
}

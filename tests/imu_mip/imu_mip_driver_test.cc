// The MIP driver end to end through a pseudo-terminal pair: set-up with
// ACK/NACK and timeouts, a faulty stream (garbage, flipped bytes, truncated
// frames, split writes), an unplug and re-plug, and the counters the
// heartbeat reports. The simulated device runs on the pty master.
#include <catch2/catch.hpp>

#include <chrono>
#include <thread>

#include "common/time/utime.h"
#include "drivers/imu_mip/imu_mip_driver.h"
#include "tests/imu_mip/simulated_mip_device.h"

using namespace vimot::mip;
using vimot::mip::test::SimulatedMipDevice;

namespace {

struct Harness {
  SimulatedMipDevice device;
  std::vector<vimot::ImuData> samples;
  std::vector<std::string> events;
  ImuMipDriver driver;

  Harness(const SimulatedMipDevice::Behaviour& behaviour, const ImuMipOptions& options)
      : device(behaviour),
        driver(
            options, [this] { return open_tty_fd(device.slave_path(), 115200); },
            [this](const vimot::ImuData& imu) { samples.push_back(imu); },
            [this](const std::string& message, bool) { events.push_back(message); }, vimot::wall_clock_utime) {}

  // Steps the driver until `done` or `seconds` pass; returns done().
  template <typename Pred>
  bool run_until(Pred done, double seconds) {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done() && std::chrono::steady_clock::now() < end) driver.step(10);
    return done();
  }

  bool has_event(const std::string& text) const {
    for (const auto& e : events) {
      if (e.find(text) != std::string::npos) return true;
    }
    return false;
  }
};

ImuMipOptions fast_options() {
  ImuMipOptions o;
  o.rate_hz = 200.0;
  o.command_timeout = 1.0;  // generous: the machine is shared, a starved device thread must not look silent
  o.reconnect_interval = 0.2;
  o.stream_timeout = 2.0;
  return o;
}

// The received samples are exactly the intact ones sent, in order, values
// and device-clock spacing intact, on a strictly increasing host time.
void check_samples(const std::vector<vimot::ImuData>& got, const std::vector<int>& good) {
  REQUIRE(got.size() == good.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    const auto expected = vimot::mip::test::test_sample(good[i], 200.0);
    CHECK(got[i].a_IinI.x() == Approx(expected.accel_g[0] * kStandardGravity).margin(1e-6));
    CHECK(got[i].w_IinI.x() == Approx(expected.gyro[0]).margin(1e-9));
    if (i > 0) CHECK(got[i].utime > got[i - 1].utime);
  }
}

}  // namespace

TEST_CASE("Set-up sequence, faulty stream, unplug and re-plug through a pty") {
  SimulatedMipDevice::Behaviour behaviour;
  behaviour.initial_packets = 5;  // the device was streaming before we opened it
  Harness h(behaviour, fast_options());

  REQUIRE(h.run_until([&] { return h.driver.streaming(); }, 5.0));
  using Cmd = std::pair<uint8_t, uint8_t>;
  CHECK(h.device.commands() == std::vector<Cmd>({{kBaseCommandSet, kCmdIdle},
                                                 {k3dmCommandSet, kCmdGetImuBaseRate},
                                                 {k3dmCommandSet, kCmdImuMessageFormat},
                                                 {k3dmCommandSet, kCmdEnableDataStream},
                                                 {kBaseCommandSet, kCmdResume}}));
  // Function 1, three descriptors at 1000 Hz / 5 = 200 Hz.
  CHECK(h.device.last_format() ==
        std::vector<uint8_t>({0x01, 0x03, kFieldScaledAccel, 0x00, 0x05, kFieldScaledGyro, 0x00, 0x05,
                              kFieldGpsTimestamp, 0x00, 0x05}));
  CHECK(h.driver.device_rate_hz() == 200.0);
  CHECK(h.driver.counters().packets_ignored >= 5);  // the stale data, not published
  CHECK(h.samples.empty());

  // 300 packets with faults.
  h.device.stream(300);
  const auto sent_after = [&](std::size_t n) { return [&h, n] { return h.device.idle_to_send() && h.samples.size() >= n; }; };
  REQUIRE(h.run_until([&] { return h.device.idle_to_send(); }, 10.0));
  const SimulatedMipDevice::Sent sent = h.device.sent();
  h.run_until(sent_after(sent.good.size()), 2.0);
  check_samples(h.samples, sent.good);
  ImuMipCounters c = h.driver.counters();
  CHECK(sent.corrupted == 12);
  CHECK(sent.truncated == 6);
  CHECK(c.samples == static_cast<int64_t>(sent.good.size()));
  CHECK(c.bytes_dropped == sent.dropped_bytes);
  CHECK(c.checksum_errors >= sent.corrupted + sent.truncated);
  CHECK(c.packets_dropped == c.checksum_errors);  // no malformed ones were sent
  CHECK(c.disconnects == 0);
  CHECK(c.reconnects == 0);

  // Unplug: the driver sees the hang-up, fails to reopen while unplugged,
  // and sets the device up again once it is back.
  h.device.unplug();
  REQUIRE(h.run_until([&] { return !h.driver.streaming(); }, 3.0));
  CHECK(h.driver.counters().disconnects == 1);
  h.run_until([] { return false; }, 0.5);  // a few failed opens
  CHECK(h.has_event("cannot open the IMU"));
  h.device.plug();
  REQUIRE(h.run_until([&] { return h.driver.streaming(); }, 5.0));
  CHECK(h.driver.counters().reconnects == 1);
  CHECK(h.device.commands().size() == 10);  // the full set-up again

  const std::size_t before = h.samples.size();
  h.device.stream(100);
  REQUIRE(h.run_until([&] { return h.device.idle_to_send(); }, 10.0));
  const SimulatedMipDevice::Sent sent2 = h.device.sent();
  h.run_until(sent_after(sent2.good.size()), 2.0);
  check_samples(h.samples, sent2.good);
  CHECK(h.samples.size() - before == sent2.good.size() - sent.good.size());
  c = h.driver.counters();
  CHECK(c.bytes_dropped == sent2.dropped_bytes);
  CHECK(c.samples_without_device_time == 0);
}

TEST_CASE("A NACK fails the set-up with the device's reason; it is retried, never streams") {
  SimulatedMipDevice::Behaviour behaviour;
  behaviour.nack_command = kCmdImuMessageFormat;
  Harness h(behaviour, fast_options());
  h.run_until([&] { return h.driver.counters().setup_failures >= 2; }, 5.0);
  const ImuMipCounters c = h.driver.counters();
  CHECK(c.setup_failures >= 2);  // retried after reconnect_interval
  CHECK(c.nacks == c.setup_failures);
  CHECK_FALSE(h.driver.streaming());
  CHECK(h.has_event("IMU message format: NACK (invalid parameter)"));
}

TEST_CASE("An unanswered command is sent again after its timeout") {
  SimulatedMipDevice::Behaviour behaviour;
  behaviour.ignore_once_command = kCmdIdle;
  Harness h(behaviour, fast_options());
  REQUIRE(h.run_until([&] { return h.driver.streaming(); }, 5.0));
  CHECK(h.driver.counters().command_timeouts == 1);
  CHECK(h.driver.counters().setup_failures == 0);
  const auto cmds = h.device.commands();
  REQUIRE(cmds.size() == 6);
  CHECK(cmds[0] == cmds[1]);  // idle twice
}

TEST_CASE("Bad driver options are refused") {
  ImuMipOptions o;
  o.rate_hz = 0.0;
  CHECK_THROWS_WITH(ImuMipDriver(o, nullptr, nullptr, nullptr, nullptr), Catch::Contains("rate_hz"));
  o = ImuMipOptions();
  o.rate_hz = 1.0;  // a sample per second cannot be watched with a 1 s timeout
  CHECK_THROWS_WITH(ImuMipDriver(o, nullptr, nullptr, nullptr, nullptr), Catch::Contains("two sample periods"));
  o = ImuMipOptions();
  o.timestamp_field = 0x0E;
  CHECK_THROWS_WITH(ImuMipDriver(o, nullptr, nullptr, nullptr, nullptr), Catch::Contains("timestamp_field"));
}

TEST_CASE("Opening an absent device fails with its name, through either byte stream") {
  CHECK_THROWS_WITH(open_serial_port("/dev/vimot_no_such_port", 115200), Catch::Contains("/dev/vimot_no_such_port"));
  CHECK_THROWS_WITH(open_tty_fd("/dev/vimot_no_such_port", 115200), Catch::Contains("/dev/vimot_no_such_port"));
  CHECK_THROWS_WITH(open_tty_fd("/dev/null", 1234), Catch::Contains("unsupported baud rate 1234"));
}

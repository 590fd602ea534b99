// The MIP parser on a real recorded device stream ($VIMOT_DATA_DIR/mip,
// SOURCE.md there): every packet decodes, counts per descriptor set match
// the recording's description, IMU values are physically sane.
// Exits 77 (ctest SKIP_RETURN_CODE) when VIMOT_DATA_DIR is unset.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>

#include "drivers/imu_mip/imu_mip_driver.h"
#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"
#include "tests/imu_mip/simulated_mip_device.h"

using namespace vimot::mip;

namespace {

constexpr int kSkip = 77;

std::vector<uint8_t> read_recording() {
  const std::string path = std::string(std::getenv("VIMOT_DATA_DIR")) + "/mip/mip_data.bin";
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace

TEST_CASE("Every packet of the recording decodes; counts per descriptor set as in SOURCE.md") {
  const std::vector<uint8_t> bytes = read_recording();
  REQUIRE(bytes.size() == 368940);

  MipParser parser;
  parser.feed(bytes.data(), bytes.size());
  std::map<int, int> per_set;
  std::vector<MipImuSample> samples;
  MipPacket packet;
  int malformed = 0;
  while (parser.next(packet)) {
    ++per_set[packet.descriptor_set];
    MipImuSample s;
    const ImuDecode d = decode_imu(packet, s);
    if (d == ImuDecode::kSample) samples.push_back(s);
    if (d == ImuDecode::kMalformed) ++malformed;
  }
  CHECK(parser.counters().packets == 8384);
  CHECK(per_set[0x80] == 7157);
  CHECK(per_set[0x82] == 714);
  CHECK(per_set[0xA0] == 512);
  CHECK(per_set[0x01] == 1);
  CHECK(per_set.size() == 4);
  CHECK(parser.counters().bytes_dropped == 0);
  CHECK(parser.counters().packets_dropped() == 0);
  CHECK(parser.pending() == 0);
  CHECK(malformed == 0);

  // 0x80 packets with accelerometer and gyro (the others carry magnetometer
  // and attitude only), each with the device's reference timestamp.
  REQUIRE(samples.size() == 4473);
  double mean_norm = 0.0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    REQUIRE(samples[i].device_time);
    if (i > 0) {
      // The device clock ticks at the 125 Hz output rate, exactly.
      REQUIRE(*samples[i].device_time - *samples[i - 1].device_time == Approx(0.008).margin(1e-9));
    }
    mean_norm += samples[i].a_IinI.norm() / static_cast<double>(samples.size());
  }
  CHECK(*samples.front().device_time == Approx(282.809).margin(1e-6));
  // The sensor is hand-moved (gyro up to ~4.5 rad/s), so only the mean
  // specific force is pinned: gravity, within 2 %.
  CHECK(mean_norm == Approx(9.80665).epsilon(0.02));
  // The first sample, read by hand from the bytes (0x3c8eaf72 = 0.017418 g ...).
  CHECK(samples.front().a_IinI.x() == Approx(0.0174176432 * 9.80665).epsilon(1e-6));
  CHECK(samples.front().a_IinI.z() == Approx(-0.9856400490 * 9.80665).epsilon(1e-6));
  CHECK(samples.front().w_IinI.z() == Approx(-0.0042687873).epsilon(1e-6));
}

TEST_CASE("The recording streamed by a simulated device through a pty: every sample reaches the driver") {
  const std::vector<uint8_t> bytes = read_recording();
  test::SimulatedMipDevice device(test::SimulatedMipDevice::Behaviour{});
  ImuMipOptions options;
  options.timestamp_field = kFieldReferenceTime;  // what this device sends
  options.command_timeout = 1.0;
  options.stream_timeout = 5.0;
  std::vector<vimot::ImuData> got;
  int64_t now = 1'700'000'000'000'000;
  ImuMipDriver driver(
      options, [&] { return open_tty_fd(device.slave_path(), 115200); },
      [&](const vimot::ImuData& imu) { got.push_back(imu); }, [](const std::string&, bool) {},
      [&] { return now += 100; });  // a host clock that only moves forward
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!driver.streaming() && std::chrono::steady_clock::now() < deadline) driver.step(10);
  REQUIRE(driver.streaming());
  device.stream_bytes(bytes);
  while ((got.size() < 4473 || !device.idle_to_send()) && std::chrono::steady_clock::now() < deadline) driver.step(10);

  REQUIRE(got.size() == 4473);
  const ImuMipCounters c = driver.counters();
  CHECK(c.bytes_dropped == 0);
  CHECK(c.packets_dropped == 0);
  CHECK(c.samples_without_device_time == 0);
  CHECK(c.packets_ignored == 8384 - 4473);  // every non-IMU packet (the set-up replies are consumed)
  double mean_norm = 0.0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    if (i > 0) REQUIRE(got[i].utime > got[i - 1].utime);
    mean_norm += got[i].a_IinI.norm() / static_cast<double>(got.size());
  }
  CHECK(mean_norm == Approx(9.80665).epsilon(0.02));
  CHECK(got.front().w_IinI.z() == Approx(-0.0042687873).epsilon(1e-6));
}

int main(int argc, char* argv[]) {
  if (!std::getenv("VIMOT_DATA_DIR")) {
    std::cout << "VIMOT_DATA_DIR not set: skipping the MIP recording test\n";
    return kSkip;
  }
  return Catch::Session().run(argc, argv);
}

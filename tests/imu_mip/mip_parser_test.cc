// The MIP parser on generated streams: every split of a packet, garbage
// between packets, truncated frames and bad checksums, with every byte
// accounted for. Values are checked against the generated ones.
#include <catch2/catch.hpp>

#include <random>

#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"
#include "tests/imu_mip/mip_test_packets.h"

using namespace vimot::mip;
using vimot::mip::test::test_packet;
using vimot::mip::test::test_sample;

namespace {

std::vector<MipPacket> drain(MipParser& parser) {
  std::vector<MipPacket> out;
  MipPacket p;
  while (parser.next(p)) out.push_back(p);
  return out;
}

// Every byte fed is in an accepted packet, dropped, or pending.
void check_accounting(const MipParser& parser, const std::vector<MipPacket>& packets) {
  int64_t accepted = 0;
  for (const MipPacket& p : packets) accepted += static_cast<int64_t>(p.payload.size() + 6);
  CHECK(accepted + parser.counters().bytes_dropped + static_cast<int64_t>(parser.pending()) ==
        parser.counters().bytes_in);
}

void check_sample(const MipPacket& packet, int k) {
  MipImuSample s;
  REQUIRE(decode_imu(packet, s) == ImuDecode::kSample);
  const auto expected = test_sample(k);
  for (int i = 0; i < 3; ++i) {
    CHECK(s.a_IinI[i] == Approx(expected.accel_g[i] * 9.80665).margin(1e-6));
    CHECK(s.w_IinI[i] == Approx(expected.gyro[i]).margin(1e-9));
  }
  REQUIRE(s.device_time);
  CHECK(*s.device_time == Approx(2300 * 604800.0 + expected.time_of_week).epsilon(1e-15));
}

}  // namespace

TEST_CASE("Fletcher checksum of a hand-computed frame") {
  // Idle command 75 65 01 02 02 02: running sums a = 0xE1, b = 0xC7 (by hand:
  // a: 75 DA DB DD DF E1; b: 75 4F 2A 07 E6 C7).
  const std::vector<uint8_t> idle = command_idle();
  REQUIRE(idle == std::vector<uint8_t>({0x75, 0x65, 0x01, 0x02, 0x02, 0x02, 0xE1, 0xC7}));
}

TEST_CASE("A packet split at every byte boundary is decoded once, values intact") {
  const std::vector<uint8_t> bytes = test_packet(3);
  for (std::size_t cut = 0; cut <= bytes.size(); ++cut) {
    MipParser parser;
    parser.feed(bytes.data(), cut);
    std::vector<MipPacket> packets = drain(parser);
    parser.feed(bytes.data() + cut, bytes.size() - cut);
    for (const MipPacket& p : drain(parser)) packets.push_back(p);
    REQUIRE(packets.size() == 1);
    check_sample(packets[0], 3);
    CHECK(parser.counters().bytes_dropped == 0);
    CHECK(parser.pending() == 0);
  }
}

TEST_CASE("A stream fed one byte at a time gives every packet in order") {
  MipParser parser;
  std::vector<MipPacket> packets;
  for (int k = 0; k < 50; ++k) {
    for (uint8_t b : test_packet(k)) {
      parser.feed(&b, 1);
      for (const MipPacket& p : drain(parser)) packets.push_back(p);
    }
  }
  REQUIRE(packets.size() == 50);
  for (int k = 0; k < 50; ++k) check_sample(packets[k], k);
  CHECK(parser.counters().bytes_dropped == 0);
  check_accounting(parser, packets);
}

TEST_CASE("Garbage between packets is dropped byte for byte, including false syncs") {
  std::mt19937 rng(7);
  std::vector<uint8_t> stream;
  int64_t garbage = 0;
  for (int k = 0; k < 200; ++k) {
    const int n = static_cast<int>(rng() % 40);
    for (int i = 0; i < n; ++i) stream.push_back(static_cast<uint8_t>(rng()));
    if (k % 10 == 0) stream.insert(stream.end(), {0x75, 0x65, 0x80, 0x10});  // a false header
    garbage += n + (k % 10 == 0 ? 4 : 0);
    const auto p = test_packet(k);
    stream.insert(stream.end(), p.begin(), p.end());
  }
  // Fed in random chunk sizes.
  MipParser parser;
  std::vector<MipPacket> packets;
  for (std::size_t pos = 0; pos < stream.size();) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % 64, stream.size() - pos);
    parser.feed(stream.data() + pos, n);
    pos += n;
    for (const MipPacket& p : drain(parser)) packets.push_back(p);
  }
  REQUIRE(packets.size() == 200);
  for (int k = 0; k < 200; ++k) check_sample(packets[k], k);
  CHECK(parser.counters().bytes_dropped == garbage);
  CHECK(parser.pending() == 0);
  // Each false header spans into the next real packet and fails its checksum.
  CHECK(parser.counters().checksum_errors >= 20);
  check_accounting(parser, packets);
}

TEST_CASE("A corrupted byte loses exactly that packet; a truncated frame loses only itself") {
  std::vector<uint8_t> stream;
  const auto p0 = test_packet(0);
  auto p1 = test_packet(1);
  const auto p2 = test_packet(2);
  const auto p3 = test_packet(3);
  p1[12] ^= 0x40;  // a bit flip in the accelerometer data
  stream.insert(stream.end(), p0.begin(), p0.end());
  stream.insert(stream.end(), p1.begin(), p1.end());
  stream.insert(stream.end(), p2.begin(), p2.begin() + 20);  // cut off mid-frame
  stream.insert(stream.end(), p3.begin(), p3.end());
  MipParser parser;
  parser.feed(stream.data(), stream.size());
  const std::vector<MipPacket> packets = drain(parser);
  REQUIRE(packets.size() == 2);
  check_sample(packets[0], 0);
  check_sample(packets[1], 3);
  CHECK(parser.counters().bytes_dropped == static_cast<int64_t>(p1.size() + 20));
  CHECK(parser.counters().checksum_errors == 2);  // the corrupt packet and the truncated one
  CHECK(parser.counters().packets_dropped() == 2);
  check_accounting(parser, packets);
}

TEST_CASE("A checksum-valid frame whose fields overrun the payload is dropped as malformed") {
  // Field length 0x20 in a 4-byte payload; the checksum is made right.
  std::vector<uint8_t> frame = {0x75, 0x65, 0x80, 0x04, 0x20, 0x04, 0x00, 0x00};
  append_u16(frame, fletcher_checksum(frame.data(), frame.size()));
  MipParser parser;
  parser.feed(frame.data(), frame.size());
  const auto p = test_packet(5);
  parser.feed(p.data(), p.size());
  const std::vector<MipPacket> packets = drain(parser);
  REQUIRE(packets.size() == 1);
  check_sample(packets[0], 5);
  CHECK(parser.counters().malformed_packets == 1);
  CHECK(parser.counters().checksum_errors == 0);
  CHECK(parser.counters().bytes_dropped == static_cast<int64_t>(frame.size()));
}

TEST_CASE("reset() drops the pending partial frame and counts it") {
  const auto p = test_packet(1);
  MipParser parser;
  parser.feed(p.data(), 10);
  CHECK(drain(parser).empty());
  CHECK(parser.pending() == 10);
  parser.reset();
  CHECK(parser.pending() == 0);
  CHECK(parser.counters().bytes_dropped == 10);
}

TEST_CASE("IMU decoding: wrong field sizes and NaN are malformed, other packets are not IMU") {
  MipImuSample s;
  std::string why;
  MipPacket packet;
  packet.descriptor_set = kSensorDataSet;
  std::vector<uint8_t> a;
  for (int i = 0; i < 3; ++i) append_f32(a, 0.0f);
  std::vector<uint8_t> w = a;

  auto build = [&](const std::vector<FieldSpec>& fields, uint8_t set = kSensorDataSet) {
    const std::vector<uint8_t> bytes = encode_packet(set, fields);
    MipParser parser;
    parser.feed(bytes.data(), bytes.size());
    REQUIRE(parser.next(packet));
  };
  build({{kFieldScaledAccel, a}});  // gyro missing
  CHECK(decode_imu(packet, s) == ImuDecode::kNotImu);
  build({{kFieldScaledAccel, a}, {kFieldScaledGyro, w}}, 0x82);
  CHECK(decode_imu(packet, s) == ImuDecode::kNotImu);
  build({{kFieldScaledAccel, {1, 2, 3}}, {kFieldScaledGyro, w}});
  CHECK(decode_imu(packet, s, &why) == ImuDecode::kMalformed);
  CHECK_THAT(why, Catch::Contains("accelerometer") && Catch::Contains("3 bytes"));
  std::vector<uint8_t> nan_w;
  append_f32(nan_w, 0.0f);
  append_f32(nan_w, std::numeric_limits<float>::quiet_NaN());
  append_f32(nan_w, 0.0f);
  build({{kFieldScaledAccel, a}, {kFieldScaledGyro, nan_w}});
  CHECK(decode_imu(packet, s, &why) == ImuDecode::kMalformed);
  CHECK_THAT(why, Catch::Contains("gyro"));
  build({{kFieldScaledAccel, a}, {kFieldScaledGyro, w}, {kFieldReferenceTime, {0, 0, 0, 1}}});
  CHECK(decode_imu(packet, s, &why) == ImuDecode::kMalformed);
  CHECK_THAT(why, Catch::Contains("reference timestamp field of 4 bytes"));
  std::vector<uint8_t> gps;
  append_f64(gps, std::numeric_limits<double>::infinity());
  append_u32(gps, 0);
  build({{kFieldScaledAccel, a}, {kFieldScaledGyro, w}, {kFieldGpsTimestamp, gps}});
  CHECK(decode_imu(packet, s, &why) == ImuDecode::kMalformed);
  CHECK_THAT(why, Catch::Contains("GPS timestamp"));
  std::vector<uint8_t> ref;
  append_u64(ref, 1'500'000'000);  // 1.5 s in ns; preferred over a GPS field
  build({{kFieldScaledAccel, a}, {kFieldScaledGyro, w}, {kFieldGpsTimestamp, gps}, {kFieldReferenceTime, ref}});
  REQUIRE(decode_imu(packet, s) == ImuDecode::kSample);
  CHECK(*s.device_time == 1.5);
  build({{kFieldScaledAccel, a}, {kFieldScaledGyro, w}});  // no timestamp: a sample without device time
  REQUIRE(decode_imu(packet, s) == ImuDecode::kSample);
  CHECK_FALSE(s.device_time);
}

TEST_CASE("Commands: IMU message format layout and ACK/NACK lookup") {
  const std::vector<uint8_t> cmd = command_imu_message_format({kFieldScaledAccel, kFieldScaledGyro}, 5);
  // payload: field len 0x0A, desc 0x08, function 1, count 2, (04 0005) (05 0005)
  REQUIRE(cmd.size() == 4 + 10 + 2);
  CHECK(std::vector<uint8_t>(cmd.begin() + 2, cmd.end() - 2) ==
        std::vector<uint8_t>({0x0C, 0x0A, 0x0A, 0x08, 0x01, 0x02, 0x04, 0x00, 0x05, 0x05, 0x00, 0x05}));
  MipParser parser;
  const auto nack = vimot::mip::test::ack_packet(k3dmCommandSet, kCmdImuMessageFormat, 0x03);
  parser.feed(nack.data(), nack.size());
  MipPacket reply;
  REQUIRE(parser.next(reply));
  CHECK_FALSE(find_ack(reply, kBaseCommandSet, kCmdImuMessageFormat));  // other set
  CHECK_FALSE(find_ack(reply, k3dmCommandSet, kCmdEnableDataStream));   // other command
  const auto ack = find_ack(reply, k3dmCommandSet, kCmdImuMessageFormat);
  REQUIRE(ack);
  CHECK_FALSE(ack->ok());
  CHECK(nack_name(ack->error) == "invalid parameter");
}

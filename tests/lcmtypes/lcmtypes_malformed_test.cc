// A malformed message must be detectable, never silently decoded:
// truncation at any byte, a wrong or corrupted fingerprint, and a corrupted
// length field. Over LCM, a typed subscriber never sees such a message while
// a raw subscriber still does (so a process can count decode errors).
#include "lcmtypes_test_util.h"

#include <exception>

using vimot_test::encode;

namespace {

// Decoding every strict prefix of a valid encoding must fail, and the full
// encoding must decode to exactly its length.
template <typename Msg>
void check_every_truncation_fails(const Msg& msg) {
  const std::vector<uint8_t> buf = encode(msg);
  for (std::size_t len = 0; len < buf.size(); ++len) {
    INFO(Msg::getTypeName() << " truncated to " << len << " of " << buf.size() << " bytes");
    Msg out{};
    CHECK(out.decode(buf.data(), 0, static_cast<int>(len)) < 0);
  }
  Msg out{};
  CHECK(out.decode(buf.data(), 0, static_cast<int>(buf.size())) ==
        static_cast<int>(buf.size()));
}

// Return value of Msg::decode over all of buf.
template <typename Msg>
int decode_as(const std::vector<uint8_t>& buf) {
  Msg out{};
  return out.decode(buf.data(), 0, static_cast<int>(buf.size()));
}

// Big-endian int32 write, as LCM encodes.
void put_i32(std::vector<uint8_t>& buf, std::size_t at, int32_t v) {
  const auto u = static_cast<uint32_t>(v);
  for (int i = 0; i < 4; ++i) buf[at + i] = static_cast<uint8_t>(u >> (24 - 8 * i));
}

}  // namespace

TEST_CASE("decoding a truncated buffer fails for fixed and variable-size types") {
  check_every_truncation_fails(vimot_test::sample_imu());
  check_every_truncation_fails(vimot_test::sample_image());
  check_every_truncation_fails(vimot_test::sample_features());
  check_every_truncation_fails(vimot_test::sample_heartbeat());
}

TEST_CASE("decoding as the wrong type or with a corrupted fingerprint fails") {
  const std::vector<uint8_t> imu = encode(vimot_test::sample_imu());
  CHECK(decode_as<vimot::ground_truth_t>(imu) < 0);
  CHECK(decode_as<vimot::nav_state_t>(imu) < 0);

  std::vector<uint8_t> corrupted = imu;
  corrupted[3] ^= 0x10;  // inside the 8-byte fingerprint
  CHECK(decode_as<vimot::imu_t>(corrupted) < 0);
}

TEST_CASE("a corrupted length field is detected, by error code or exception") {
  // lcm-gen 1.3.1 C++ code resizes a vector to a decoded length before it
  // checks the buffer, so a negative length throws (std::length_error)
  // instead of returning < 0. Code decoding untrusted bytes must catch.
  const auto decodes_ok = [](const std::vector<uint8_t>& buf) {
    vimot::image_t out{};
    try {
      return out.decode(buf.data(), 0, static_cast<int>(buf.size())) >= 0;
    } catch (const std::exception&) {
      return false;
    }
  };
  const vimot::image_t image = vimot_test::sample_image();
  const std::vector<uint8_t> good = encode(image);
  REQUIRE(decodes_ok(good));
  // Layout: fingerprint(8) utime(8) width height row_stride pixelformat size(4 each)
  constexpr std::size_t kSizeAt = 8 + 8 + 4 * 4;

  std::vector<uint8_t> bad = good;
  put_i32(bad, kSizeAt, -5);
  CHECK_FALSE(decodes_ok(bad));
  // One byte more than present: everything after is read shifted by a byte.
  put_i32(bad, kSizeAt, image.size + 1);
  CHECK_FALSE(decodes_ok(bad));
  // More bytes than the whole buffer.
  put_i32(bad, kSizeAt, static_cast<int32_t>(good.size()));
  CHECK_FALSE(decodes_ok(bad));
}

namespace {
struct RawCounter {
  void on_raw(const lcm::ReceiveBuffer* /*rbuf*/, const std::string& /*channel*/) { ++count; }
  int count{0};
};
}  // namespace

TEST_CASE("a typed subscriber never receives a truncated message; a raw one does") {
  lcm::LCM lcm("memq://");
  REQUIRE(lcm.good());
  vimot_test::Receiver<vimot::imu_t> typed;
  RawCounter raw;
  lcm.subscribe("IMU", &vimot_test::Receiver<vimot::imu_t>::on_message, &typed);
  lcm.subscribe("IMU", &RawCounter::on_raw, &raw);

  const std::vector<uint8_t> buf = encode(vimot_test::sample_imu());
  // LCM prints "error -1 decoding imu_t!!!" to stderr here; that is expected.
  REQUIRE(lcm.publish("IMU", buf.data(), static_cast<unsigned>(buf.size() - 1)) == 0);
  REQUIRE(lcm.handleTimeout(1000) > 0);
  CHECK(raw.count == 1);
  CHECK(typed.count == 0);

  REQUIRE(lcm.publish("IMU", buf.data(), static_cast<unsigned>(buf.size())) == 0);
  REQUIRE(lcm.handleTimeout(1000) > 0);
  CHECK(raw.count == 2);
  CHECK(typed.count == 1);
}

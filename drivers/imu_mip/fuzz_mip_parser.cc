// libFuzzer target: arbitrary bytes through the MIP parser and every decoder
// (IMU sample, ACK/NACK, base-rate reply). Built only with -DVIMOT_FUZZ=ON
// (clang); run by scripts/fuzz.sh. Aborts if the parser's byte accounting
// breaks.
//
// The first byte chooses the chunk size (so splits at every boundary get
// tried) and the mode: raw, the input is the serial stream itself; reframed,
// the input is a list of (set, length, payload) records framed with a valid
// checksum — random bytes almost never pass a Fletcher checksum, and without
// this the decoders would only ever see the seed corpus's packets.
#include <cstdlib>

#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"

namespace {

std::vector<uint8_t> reframe(const uint8_t* data, std::size_t size) {
  using namespace vimot::mip;
  std::vector<uint8_t> out;
  std::size_t pos = 0;
  while (pos + 2 <= size) {
    const uint8_t set = data[pos];
    const std::size_t length = std::min<std::size_t>(data[pos + 1], size - pos - 2);
    const std::size_t start = out.size();
    out.insert(out.end(), {kSync1, kSync2, set, static_cast<uint8_t>(length)});
    out.insert(out.end(), data + pos + 2, data + pos + 2 + length);
    append_u16(out, fletcher_checksum(out.data() + start, out.size() - start));
    pos += 2 + length;
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vimot::mip;
  if (size == 0) return 0;
  // High bit: mode (clear for 0x75, so the recording's slices stay raw).
  const std::size_t chunk = 1 + (data[0] & 0x7F);
  std::vector<uint8_t> framed;
  if (data[0] & 0x80) {
    framed = reframe(data + 1, size - 1);
    data = framed.data();
    size = framed.size();
  }

  MipParser parser;
  MipPacket packet;
  MipImuSample sample;
  std::string why;
  int64_t accepted_bytes = 0;
  for (std::size_t pos = 0; pos < size; pos += chunk) {
    parser.feed(data + pos, std::min(chunk, size - pos));
    while (parser.next(packet)) {
      accepted_bytes += static_cast<int64_t>(packet.payload.size() + kHeaderSize + kChecksumSize);
      decode_imu(packet, sample, &why);
      for (uint8_t set : {kBaseCommandSet, k3dmCommandSet}) {
        for (uint8_t cmd : {kCmdIdle, kCmdResume, kCmdGetImuBaseRate, kCmdImuMessageFormat, kCmdEnableDataStream}) {
          if (const auto ack = find_ack(packet, set, cmd)) nack_name(ack->error);
        }
      }
      find_imu_base_rate(packet);
    }
  }
  const MipParserCounters& c = parser.counters();
  if (accepted_bytes + c.bytes_dropped + static_cast<int64_t>(parser.pending()) != c.bytes_in) std::abort();
  const int64_t dropped_before_reset = c.bytes_dropped;
  const std::size_t pending = parser.pending();
  parser.reset();
  if (parser.counters().bytes_dropped != dropped_before_reset + static_cast<int64_t>(pending)) std::abort();
  return 0;
}

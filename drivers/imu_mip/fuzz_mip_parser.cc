// libFuzzer target: arbitrary bytes, fed in fuzzer-chosen chunk sizes,
// through the MIP parser and the IMU decoder. Built only with -DVIMOT_FUZZ=ON
// (clang); run by scripts/fuzz.sh. Checks the parser's byte accounting.
#include <cstdlib>

#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace vimot::mip;
  MipParser parser;
  MipPacket packet;
  MipImuSample sample;
  int64_t accepted_bytes = 0;
  // The first byte picks the chunk size, so splits at every boundary get tried.
  const std::size_t chunk = size > 0 ? 1 + data[0] : 1;
  for (std::size_t pos = 0; pos < size; pos += chunk) {
    parser.feed(data + pos, std::min(chunk, size - pos));
    while (parser.next(packet)) {
      accepted_bytes += static_cast<int64_t>(packet.payload.size() + kHeaderSize + kChecksumSize);
      decode_imu(packet, sample);
      find_ack(packet, kBaseCommandSet, kCmdIdle);
      find_imu_base_rate(packet);
    }
  }
  const MipParserCounters& c = parser.counters();
  if (accepted_bytes + c.bytes_dropped + static_cast<int64_t>(parser.pending()) != c.bytes_in) std::abort();
  return 0;
}

#pragma once
// A streaming MIP packet parser: bytes in any chunking, checksum-valid
// packets out. It resynchronises on garbage, truncated frames and checksum
// errors, and accounts for every byte: each byte fed ends up in exactly one
// accepted packet, in bytes_dropped, or still pending().
//
// Resynchronisation: bytes before a sync pair are dropped; a candidate frame
// whose checksum fails drops only its first byte and the scan restarts one
// byte later, so a real packet that begins inside a truncated frame is found.
// A frame waits for its full length before it is judged, so a frame cut short
// by a new packet is judged (and fails) once the new packet's bytes arrive.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "drivers/imu_mip/mip_protocol.h"

namespace vimot::mip {

struct MipParserCounters {
  int64_t bytes_in{0};
  int64_t packets{0};            // accepted packets
  int64_t bytes_dropped{0};      // bytes that are part of no accepted packet
  int64_t checksum_errors{0};    // candidate frames whose checksum failed (includes false syncs in garbage)
  int64_t malformed_packets{0};  // checksum-valid frames whose fields do not tile the payload

  /// Candidate frames discarded for any reason.
  int64_t packets_dropped() const { return checksum_errors + malformed_packets; }
};

class MipParser {
 public:
  void feed(const uint8_t* data, std::size_t size);

  /// The next complete packet; false when more bytes are needed.
  bool next(MipPacket& packet);

  /// Discards the pending bytes (counted as dropped), e.g. after a reconnect.
  void reset();

  std::size_t pending() const { return buffer_.size() - start_; }
  const MipParserCounters& counters() const { return counters_; }

 private:
  void drop(std::size_t n);

  std::vector<uint8_t> buffer_;
  std::size_t start_{0};  // first unconsumed byte; the front is compacted lazily
  MipParserCounters counters_;
};

}  // namespace vimot::mip

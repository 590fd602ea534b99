#include "drivers/imu_mip/mip_parser.h"

#include <algorithm>

namespace vimot::mip {

namespace {
// Consumed bytes are erased only once they are this many and at least half
// the buffer, so a long stream costs amortised O(1) per byte.
constexpr std::size_t kCompactThreshold = 4096;
}  // namespace

void MipParser::feed(const uint8_t* data, std::size_t size) {
  counters_.bytes_in += static_cast<int64_t>(size);
  if (start_ >= kCompactThreshold && start_ * 2 >= buffer_.size()) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(start_));
    start_ = 0;
  }
  buffer_.insert(buffer_.end(), data, data + size);
}

void MipParser::drop(std::size_t n) {
  counters_.bytes_dropped += static_cast<int64_t>(n);
  start_ += n;
}

void MipParser::reset() {
  drop(pending());
  buffer_.clear();
  start_ = 0;
}

bool MipParser::next(MipPacket& packet) {
  for (;;) {
    // Skip to the next sync pair; a lone trailing 0x75 may be its first half.
    const auto begin = buffer_.begin() + static_cast<std::ptrdiff_t>(start_);
    auto sync = begin;
    while (sync != buffer_.end()) {
      sync = std::find(sync, buffer_.end(), kSync1);
      if (sync == buffer_.end() || sync + 1 == buffer_.end() || sync[1] == kSync2) break;
      ++sync;
    }
    drop(static_cast<std::size_t>(sync - begin));
    if (pending() < kHeaderSize) return false;

    const uint8_t* frame = buffer_.data() + start_;
    const std::size_t payload_size = frame[3];
    const std::size_t frame_size = kHeaderSize + payload_size + kChecksumSize;
    if (pending() < frame_size) return false;

    const uint16_t expected = read_u16(frame + kHeaderSize + payload_size);
    if (fletcher_checksum(frame, kHeaderSize + payload_size) != expected) {
      ++counters_.checksum_errors;
      drop(1);
      continue;
    }
    packet.descriptor_set = frame[2];
    packet.payload.assign(frame + kHeaderSize, frame + kHeaderSize + payload_size);
    if (!split_fields(packet.payload, packet.fields)) {
      ++counters_.malformed_packets;
      drop(frame_size);
      continue;
    }
    start_ += frame_size;
    ++counters_.packets;
    return true;
  }
}

}  // namespace vimot::mip

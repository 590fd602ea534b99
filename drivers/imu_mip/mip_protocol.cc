#include "drivers/imu_mip/mip_protocol.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace vimot::mip {

uint16_t fletcher_checksum(const uint8_t* data, std::size_t size) {
  uint8_t a = 0;
  uint8_t b = 0;
  for (std::size_t i = 0; i < size; ++i) {
    a = static_cast<uint8_t>(a + data[i]);
    b = static_cast<uint8_t>(b + a);
  }
  return static_cast<uint16_t>((a << 8) | b);
}

const MipField* MipPacket::find(uint8_t field_descriptor) const {
  for (const MipField& f : fields) {
    if (f.descriptor == field_descriptor) return &f;
  }
  return nullptr;
}

bool split_fields(const std::vector<uint8_t>& payload, std::vector<MipField>& fields) {
  fields.clear();
  std::size_t pos = 0;
  while (pos < payload.size()) {
    if (payload.size() - pos < kFieldHeaderSize) return false;
    const std::size_t length = payload[pos];
    if (length < kFieldHeaderSize || length > payload.size() - pos) return false;
    fields.push_back({payload[pos + 1], static_cast<uint8_t>(pos + kFieldHeaderSize),
                      static_cast<uint8_t>(length - kFieldHeaderSize)});
    pos += length;
  }
  return true;
}

std::vector<uint8_t> encode_packet(uint8_t descriptor_set, const std::vector<FieldSpec>& fields) {
  std::vector<uint8_t> out = {kSync1, kSync2, descriptor_set, 0};
  for (const FieldSpec& f : fields) {
    const std::size_t length = f.data.size() + kFieldHeaderSize;
    if (length > kMaxPayloadSize || out.size() - kHeaderSize + length > kMaxPayloadSize) {
      throw std::invalid_argument("MIP packet: fields of " + std::to_string(out.size() - kHeaderSize + length) +
                                  " bytes exceed the 255-byte payload");
    }
    out.push_back(static_cast<uint8_t>(length));
    out.push_back(f.descriptor);
    out.insert(out.end(), f.data.begin(), f.data.end());
  }
  out[3] = static_cast<uint8_t>(out.size() - kHeaderSize);
  const uint16_t checksum = fletcher_checksum(out.data(), out.size());
  append_u16(out, checksum);
  return out;
}

uint16_t read_u16(const uint8_t* p) { return static_cast<uint16_t>((p[0] << 8) | p[1]); }

uint32_t read_u32(const uint8_t* p) {
  return (static_cast<uint32_t>(p[0]) << 24) | (static_cast<uint32_t>(p[1]) << 16) |
         (static_cast<uint32_t>(p[2]) << 8) | static_cast<uint32_t>(p[3]);
}

uint64_t read_u64(const uint8_t* p) { return (static_cast<uint64_t>(read_u32(p)) << 32) | read_u32(p + 4); }

float read_f32(const uint8_t* p) {
  const uint32_t bits = read_u32(p);
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

double read_f64(const uint8_t* p) {
  const uint64_t bits = read_u64(p);
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

void append_u16(std::vector<uint8_t>& out, uint16_t v) {
  out.push_back(static_cast<uint8_t>(v >> 8));
  out.push_back(static_cast<uint8_t>(v));
}

void append_u32(std::vector<uint8_t>& out, uint32_t v) {
  append_u16(out, static_cast<uint16_t>(v >> 16));
  append_u16(out, static_cast<uint16_t>(v));
}

void append_u64(std::vector<uint8_t>& out, uint64_t v) {
  append_u32(out, static_cast<uint32_t>(v >> 32));
  append_u32(out, static_cast<uint32_t>(v));
}

void append_f32(std::vector<uint8_t>& out, float v) {
  uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  append_u32(out, bits);
}

void append_f64(std::vector<uint8_t>& out, double v) {
  uint64_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  append_u64(out, bits);
}

}  // namespace vimot::mip

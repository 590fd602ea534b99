#pragma once
// The MIP framing (LORD / HBK MicroStrain inertial sensors, 3DM-GX4 family
// and later): a packet is
//   0x75 0x65 | descriptor set | payload length | payload | Fletcher MSB LSB
// and its payload is a sequence of fields, each
//   field length (including these 2 bytes) | field descriptor | data.
// All multi-byte values are big-endian. No I/O here.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace vimot::mip {

constexpr uint8_t kSync1 = 0x75;
constexpr uint8_t kSync2 = 0x65;
constexpr std::size_t kHeaderSize = 4;    // sync1, sync2, descriptor set, payload length
constexpr std::size_t kChecksumSize = 2;
constexpr std::size_t kMaxPayloadSize = 255;
constexpr std::size_t kFieldHeaderSize = 2;  // field length, field descriptor

/// The 2-byte Fletcher checksum over header and payload (MSB first on the wire).
uint16_t fletcher_checksum(const uint8_t* data, std::size_t size);

/// One field of a packet: its data is payload[offset, offset + size).
struct MipField {
  uint8_t descriptor{0};
  uint8_t offset{0};
  uint8_t size{0};  // data bytes, without the 2-byte field header
};

/// A checksum-valid packet whose fields tile the payload exactly.
struct MipPacket {
  uint8_t descriptor_set{0};
  std::vector<uint8_t> payload;
  std::vector<MipField> fields;

  const uint8_t* data(const MipField& field) const { return payload.data() + field.offset; }
  /// The first field with this descriptor, nullptr if none.
  const MipField* find(uint8_t field_descriptor) const;
};

/// Splits a payload into fields. Returns false (and leaves `fields` partial)
/// when a field length is below 2 or runs past the payload.
bool split_fields(const std::vector<uint8_t>& payload, std::vector<MipField>& fields);

/// A field to encode: descriptor and data (at most 253 bytes).
struct FieldSpec {
  uint8_t descriptor{0};
  std::vector<uint8_t> data;
};

/// A complete wire packet with checksum; throws std::invalid_argument if the
/// fields do not fit in one packet.
std::vector<uint8_t> encode_packet(uint8_t descriptor_set, const std::vector<FieldSpec>& fields);

// Big-endian readers and writers for field data.
uint16_t read_u16(const uint8_t* p);
uint32_t read_u32(const uint8_t* p);
uint64_t read_u64(const uint8_t* p);
float read_f32(const uint8_t* p);
double read_f64(const uint8_t* p);
void append_u16(std::vector<uint8_t>& out, uint16_t v);
void append_u32(std::vector<uint8_t>& out, uint32_t v);
void append_u64(std::vector<uint8_t>& out, uint64_t v);
void append_f32(std::vector<uint8_t>& out, float v);
void append_f64(std::vector<uint8_t>& out, double v);

}  // namespace vimot::mip

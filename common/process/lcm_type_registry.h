#pragma once
// Every vimot message type, found by the 8-byte fingerprint that starts each
// encoded LCM message. Lets log tools name and fully decode any vimot
// message without knowing its channel.

#include <cstdint>
#include <string>
#include <vector>

namespace vimot {

struct LcmTypeInfo {
  std::string name;   // e.g. "vimot.imu_t"
  int64_t fingerprint{0};
  /// Decodes `size` bytes; true if they are exactly one well-formed message.
  bool (*decodes)(const void* data, int size){nullptr};
};

const std::vector<LcmTypeInfo>& vimot_lcm_types();

/// The type whose fingerprint starts `data`, or nullptr (not a vimot type,
/// or fewer than 8 bytes).
const LcmTypeInfo* find_lcm_type(const void* data, int size);

}  // namespace vimot

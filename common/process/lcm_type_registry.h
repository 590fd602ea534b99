#pragma once
// Every vimot message type, found by the 8-byte fingerprint that starts each
// encoded LCM message, with its wire layout. Lets log tools name and fully
// decode any vimot message without knowing its channel, and lets every
// decoder of outside bytes check the lengths before it allocates.

#include <cstdint>
#include <exception>
#include <string>
#include <vector>

#include "common/process/lcm_layout.h"

namespace vimot {

struct LcmTypeInfo {
  std::string name;   // e.g. "vimot.imu_t"
  int64_t fingerprint{0};
  const LcmStruct* layout{nullptr};
  /// Decodes `size` bytes; true if they are exactly one well-formed message.
  bool (*decodes)(const void* data, int size){nullptr};
};

/// Throws std::logic_error on first use if a layout no longer matches the
/// fingerprint lcm-gen computed from its .lcm file.
const std::vector<LcmTypeInfo>& vimot_lcm_types();

/// The type whose fingerprint starts `data`, or nullptr (not a vimot type,
/// or fewer than 8 bytes).
const LcmTypeInfo* find_lcm_type(const void* data, int size);

/// The utime of an encoded vimot message (every vimot type starts with it,
/// right after the fingerprint); -1 if `size` < 16.
int64_t vimot_message_utime(const void* data, int size);

/// The layout of the vimot type with this fingerprint; throws
/// std::logic_error naming `type_name` if it is not a registered vimot type.
const LcmStruct& vimot_lcm_layout(int64_t fingerprint, const std::string& type_name);

/// Decodes bytes from outside (network, log) as Msg: false, without
/// allocating, if a length cannot fit in `size` (see lcm_layout.h); false if
/// the generated decoder rejects them or they hold more than one message.
template <typename Msg>
bool decode_untrusted(const void* data, int size, Msg* msg) {
  static const LcmStruct& layout = vimot_lcm_layout(Msg::getHash(), Msg::getTypeName());
  if (!lcm_lengths_fit(layout, data, size)) return false;
  // Defence in depth: lcm-gen 1.3 decoders throw (length_error, bad_alloc)
  // on corrupt lengths instead of returning < 0.
  try {
    return msg->decode(data, 0, size) == size;
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace vimot

// libFuzzer target: bytes from the network or a log, decoded as every vimot
// type through the same check every subscriber and vimot-log-summary use
// (decode_untrusted: lengths against the bytes left, then the generated
// decoder). Run with -malloc_limit_mb so an allocation out of proportion to
// the input counts as a crash.
//
// Input: byte 0 picks the type (index into vimot_lcm_types()), the rest is
// the message after its 8-byte fingerprint, so every input reaches a decoder
// body instead of failing the fingerprint compare.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/process/lcm_type_registry.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1 || size > (1u << 24)) return 0;
  const std::vector<vimot::LcmTypeInfo>& types = vimot::vimot_lcm_types();
  const vimot::LcmTypeInfo& type = types[data[0] % types.size()];
  std::vector<uint8_t> message(8 + size - 1);
  const auto fp = static_cast<uint64_t>(type.fingerprint);
  for (int i = 0; i < 8; ++i) message[static_cast<std::size_t>(i)] = static_cast<uint8_t>(fp >> (56 - 8 * i));
  std::copy(data + 1, data + size, message.begin() + 8);
  type.decodes(message.data(), static_cast<int>(message.size()));
  // The raw bytes too, as vimot-log-summary meets them.
  if (const vimot::LcmTypeInfo* raw = vimot::find_lcm_type(data, static_cast<int>(size))) {
    raw->decodes(data, static_cast<int>(size));
  }
  return 0;
}

#pragma once
// The wire layout of an LCM struct, and a walk over encoded bytes that checks
// every array and string length against the bytes that remain, before a
// generated decoder allocates. lcm-gen 1.3 C++ decoders resize a vector to a
// length read from the wire and only then check the buffer: a 20-byte
// message claiming 1e8 elements allocates gigabytes. The walk allocates
// nothing and reads each byte at most once.
//
// A layout is written by hand from the .lcm file; lcm_fingerprint() hashes it
// the way lcm-gen does, so a layout that drifts from its .lcm file is caught
// by comparing with the generated getHash().

#include <cstdint>
#include <string>
#include <vector>

namespace vimot {

enum class LcmKind { kInt8, kInt16, kInt32, kInt64, kFloat, kDouble, kBoolean, kByte, kString, kStruct };

struct LcmStruct;

/// One member: a scalar, or a one-dimensional array whose size is a number
/// ("4") or the name of an earlier integer member ("num_obs").
struct LcmField {
  LcmField(std::string name, LcmKind kind, std::string dim = "");
  LcmField(std::string name, const LcmStruct& type, std::string dim = "");

  std::string name;
  LcmKind kind;
  const LcmStruct* type{nullptr};  // kStruct only
  std::string dim;                 // empty: scalar
  // Resolved by LcmStruct: the element count of a constant dimension, or the
  // index of the member holding the count (-1 for a constant or a scalar).
  int64_t fixed_count{1};
  int count_member{-1};
};

struct LcmStruct {
  /// Resolves dimensions; throws std::logic_error on a dimension that is not
  /// a number or an earlier integer member.
  LcmStruct(std::string name, std::vector<LcmField> fields);

  std::string name;
  std::vector<LcmField> fields;
  int64_t min_size{0};  // encoded bytes with every variable array empty
  bool fixed_size{true};  // no strings or variable arrays anywhere inside
};

/// The fingerprint lcm-gen's C++ getHash() returns for this layout.
int64_t lcm_fingerprint(const LcmStruct& layout);

/// True if `size` bytes (8-byte fingerprint, then the body) hold exactly one
/// message of this layout: every length is non-negative and fits in the
/// bytes that remain, and nothing is left over. The fingerprint itself is
/// not compared (the generated decoder does that).
bool lcm_lengths_fit(const LcmStruct& layout, const void* data, int size);

}  // namespace vimot

#include "common/process/lcm_layout.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace vimot {

namespace {

bool is_integer(LcmKind k) {
  return k == LcmKind::kInt8 || k == LcmKind::kInt16 || k == LcmKind::kInt32 || k == LcmKind::kInt64;
}

// Encoded bytes of one primitive element; a string's is its minimum (an
// int32 length and the terminating NUL).
int64_t primitive_size(LcmKind k) {
  switch (k) {
    case LcmKind::kInt8:
    case LcmKind::kBoolean:
    case LcmKind::kByte: return 1;
    case LcmKind::kInt16: return 2;
    case LcmKind::kInt32:
    case LcmKind::kFloat: return 4;
    case LcmKind::kInt64:
    case LcmKind::kDouble: return 8;
    case LcmKind::kString: return 5;
    case LcmKind::kStruct: break;
  }
  throw std::logic_error("primitive_size of a struct");
}

const char* primitive_name(LcmKind k) {
  switch (k) {
    case LcmKind::kInt8: return "int8_t";
    case LcmKind::kInt16: return "int16_t";
    case LcmKind::kInt32: return "int32_t";
    case LcmKind::kInt64: return "int64_t";
    case LcmKind::kFloat: return "float";
    case LcmKind::kDouble: return "double";
    case LcmKind::kBoolean: return "boolean";
    case LcmKind::kByte: return "byte";
    case LcmKind::kString: return "string";
    case LcmKind::kStruct: break;
  }
  throw std::logic_error("primitive_name of a struct");
}

int64_t element_min_size(const LcmField& f) {
  return f.kind == LcmKind::kStruct ? f.type->min_size : primitive_size(f.kind);
}

bool element_fixed_size(const LcmField& f) {
  return f.kind == LcmKind::kStruct ? f.type->fixed_size : f.kind != LcmKind::kString;
}

// Big-endian signed integer of `bytes` bytes, as LCM encodes.
int64_t read_int(const uint8_t* p, int bytes) {
  uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  const int shift = 64 - 8 * bytes;
  return static_cast<int64_t>(v << shift) >> shift;  // sign-extend
}

// Bytes one message of `s` occupies at p (at most n), or -1 if a length does
// not fit. Recursion depth is the nesting of the layout, not of the input.
int64_t walk(const LcmStruct& s, const uint8_t* p, int64_t n) {
  int64_t pos = 0;
  std::vector<int64_t> counts(s.fields.size(), 0);
  for (std::size_t i = 0; i < s.fields.size(); ++i) {
    const LcmField& f = s.fields[i];
    const int64_t count = f.count_member >= 0 ? counts[static_cast<std::size_t>(f.count_member)] : f.fixed_count;
    const int64_t elem_min = std::max<int64_t>(element_min_size(f), 1);
    // Checked before any element is looked at: this is what rejects a huge
    // count in a short message without touching its (absent) elements.
    if (count < 0 || count > (n - pos) / elem_min) return -1;
    if (element_fixed_size(f)) {
      if (is_integer(f.kind) && f.dim.empty()) counts[i] = read_int(p + pos, static_cast<int>(elem_min));
      pos += count * elem_min;
      continue;
    }
    for (int64_t k = 0; k < count; ++k) {
      if (f.kind == LcmKind::kString) {
        if (n - pos < 4) return -1;
        const int64_t len = read_int(p + pos, 4);  // including the NUL
        pos += 4;
        if (len < 1 || len > n - pos) return -1;
        pos += len;
      } else {
        const int64_t used = walk(*f.type, p + pos, n - pos);
        if (used < 0) return -1;
        pos += used;
      }
    }
  }
  return pos;
}

// lcm-gen's signature hash (lcmgen.c): member names, primitive type names and
// dimensions, in order; a struct's name is not part of it.
int64_t hash_update(int64_t v, char c) {
  const auto u = static_cast<uint64_t>(v);
  return static_cast<int64_t>(((u << 8) ^ static_cast<uint64_t>(v >> 55)) + static_cast<uint64_t>(c));
}

int64_t hash_string_update(int64_t v, const std::string& s) {
  v = hash_update(v, static_cast<char>(s.size()));
  for (char c : s) v = hash_update(v, c);
  return v;
}

// The generated _computeHash(): own signature plus each struct member's,
// rotated left by one.
uint64_t computed_hash(const LcmStruct& s) {
  int64_t v = 0x12345678;
  for (const LcmField& f : s.fields) {
    v = hash_string_update(v, f.name);
    if (f.kind != LcmKind::kStruct) v = hash_string_update(v, primitive_name(f.kind));
    v = hash_update(v, static_cast<char>(f.dim.empty() ? 0 : 1));
    if (!f.dim.empty()) {
      v = hash_update(v, static_cast<char>(f.count_member >= 0 ? 1 : 0));  // LCM_VAR : LCM_CONST
      v = hash_string_update(v, f.dim);
    }
  }
  uint64_t h = static_cast<uint64_t>(v);
  for (const LcmField& f : s.fields) {
    if (f.kind == LcmKind::kStruct) h += computed_hash(*f.type);
  }
  return (h << 1) + ((h >> 63) & 1);
}

}  // namespace

LcmField::LcmField(std::string name_, LcmKind kind_, std::string dim_)
    : name(std::move(name_)), kind(kind_), dim(std::move(dim_)) {
  if (kind == LcmKind::kStruct) throw std::logic_error("LcmField " + name + ": a struct member needs its layout");
}

LcmField::LcmField(std::string name_, const LcmStruct& type_, std::string dim_)
    : name(std::move(name_)), kind(LcmKind::kStruct), type(&type_), dim(std::move(dim_)) {}

LcmStruct::LcmStruct(std::string name_, std::vector<LcmField> fields_)
    : name(std::move(name_)), fields(std::move(fields_)) {
  for (std::size_t i = 0; i < fields.size(); ++i) {
    LcmField& f = fields[i];
    if (!f.dim.empty()) {
      if (std::isdigit(static_cast<unsigned char>(f.dim[0]))) {
        f.fixed_count = std::stoll(f.dim);
      } else {
        const auto it = std::find_if(fields.begin(), fields.begin() + static_cast<std::ptrdiff_t>(i),
                                     [&](const LcmField& g) { return g.name == f.dim; });
        if (it == fields.begin() + static_cast<std::ptrdiff_t>(i) || !is_integer(it->kind) || !it->dim.empty()) {
          throw std::logic_error(name + "." + f.name + ": dimension '" + f.dim +
                                 "' is neither a number nor an earlier integer member");
        }
        f.count_member = static_cast<int>(it - fields.begin());
      }
    }
    if (f.count_member >= 0 || !element_fixed_size(f)) fixed_size = false;
    if (f.count_member < 0) min_size += f.fixed_count * element_min_size(f);
  }
}

int64_t lcm_fingerprint(const LcmStruct& layout) { return static_cast<int64_t>(computed_hash(layout)); }

bool lcm_lengths_fit(const LcmStruct& layout, const void* data, int size) {
  if (data == nullptr || size < 8) return false;
  const int64_t body = size - 8;
  return walk(layout, static_cast<const uint8_t*>(data) + 8, body) == body;
}

}  // namespace vimot

#pragma once
// Minimal JSON, hand-written (vimot adds no JSON dependency): a streaming
// writer for the evaluators' summaries and a small parser to read them back
// (`vimot-log-eval --compare`). Numbers are written with 17 significant
// digits (a double round-trips); non-finite numbers become null.

#include <cstdint>
#include <utility>
#include <stdexcept>
#include <string>
#include <vector>

namespace vimot {
namespace eval {

class JsonWriter {
 public:
  explicit JsonWriter(int indent = 2) : indent_(indent) {}

  JsonWriter& begin_object();
  JsonWriter& end_object();
  JsonWriter& begin_array();
  JsonWriter& end_array();
  /// The key of the next value, inside an object.
  JsonWriter& key(const std::string& k);
  JsonWriter& value(double v);
  JsonWriter& value(int64_t v);
  JsonWriter& value(uint64_t v);
  JsonWriter& value(int v) { return value(static_cast<int64_t>(v)); }
  JsonWriter& value(bool v);
  JsonWriter& value(const std::string& v);
  JsonWriter& value(const char* v) { return value(std::string(v)); }
  JsonWriter& null();
  template <typename T>
  JsonWriter& field(const std::string& k, const T& v) {
    key(k);
    return value(v);
  }

  /// The document; throws std::logic_error if objects or arrays are open.
  std::string str() const;

 private:
  void before_value();
  void newline();

  int indent_;
  std::string out_;
  std::vector<char> stack_;        // '{' or '['
  std::vector<bool> has_items_;
  bool after_key_{false};
};

/// A parsed JSON value.
class JsonValue {
 public:
  enum class Kind { kNull, kBool, kNumber, kString, kArray, kObject };

  static JsonValue parse(const std::string& text);  // throws std::runtime_error with the offset

  Kind kind() const { return kind_; }
  bool is_object() const { return kind_ == Kind::kObject; }
  bool has(const std::string& key) const;
  /// Object member; throws std::runtime_error if absent or not an object.
  const JsonValue& at(const std::string& key) const;
  /// Array element; throws if out of range or not an array.
  const JsonValue& at(std::size_t index) const;
  std::size_t size() const;  // array or object size
  double number() const;     // throws unless a number (null reads as NaN)
  bool boolean() const;
  const std::string& string() const;

 private:
  friend class JsonParser;
  Kind kind_{Kind::kNull};
  bool bool_{false};
  double number_{0.0};
  std::string string_;
  std::vector<JsonValue> array_;
  std::vector<std::pair<std::string, JsonValue>> object_;  // in file order
};

}  // namespace eval
}  // namespace vimot

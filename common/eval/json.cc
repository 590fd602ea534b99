#include "common/eval/json.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace vimot {
namespace eval {

// ------------------------------------------------------------------ writer
void JsonWriter::newline() {
  if (indent_ <= 0) return;
  out_ += '\n';
  out_.append(stack_.size() * static_cast<std::size_t>(indent_), ' ');
}

void JsonWriter::before_value() {
  if (after_key_) {
    after_key_ = false;
    return;
  }
  if (stack_.empty()) {
    if (!out_.empty()) throw std::logic_error("JsonWriter: more than one top-level value");
    return;
  }
  if (stack_.back() == '{') throw std::logic_error("JsonWriter: a value in an object needs key() first");
  if (has_items_.back()) out_ += ',';
  has_items_.back() = true;
  newline();
}

JsonWriter& JsonWriter::begin_object() {
  before_value();
  out_ += '{';
  stack_.push_back('{');
  has_items_.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::end_object() {
  if (stack_.empty() || stack_.back() != '{' || after_key_) throw std::logic_error("JsonWriter: unbalanced end_object");
  const bool items = has_items_.back();
  stack_.pop_back();
  has_items_.pop_back();
  if (items) newline();
  out_ += '}';
  return *this;
}

JsonWriter& JsonWriter::begin_array() {
  before_value();
  out_ += '[';
  stack_.push_back('[');
  has_items_.push_back(false);
  return *this;
}

JsonWriter& JsonWriter::end_array() {
  if (stack_.empty() || stack_.back() != '[') throw std::logic_error("JsonWriter: unbalanced end_array");
  const bool items = has_items_.back();
  stack_.pop_back();
  has_items_.pop_back();
  if (items) newline();
  out_ += ']';
  return *this;
}

namespace {
std::string quote(const std::string& s) {
  std::string q = "\"";
  for (unsigned char c : s) {
    switch (c) {
      case '"': q += "\\\""; break;
      case '\\': q += "\\\\"; break;
      case '\n': q += "\\n"; break;
      case '\r': q += "\\r"; break;
      case '\t': q += "\\t"; break;
      default:
        if (c < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          q += buf;
        } else {
          q += static_cast<char>(c);
        }
    }
  }
  return q + "\"";
}
}  // namespace

JsonWriter& JsonWriter::key(const std::string& k) {
  if (stack_.empty() || stack_.back() != '{' || after_key_) throw std::logic_error("JsonWriter: key outside an object");
  if (has_items_.back()) out_ += ',';
  has_items_.back() = true;
  newline();
  out_ += quote(k);
  out_ += indent_ > 0 ? ": " : ":";
  after_key_ = true;
  return *this;
}

JsonWriter& JsonWriter::value(double v) {
  if (!std::isfinite(v)) return null();
  before_value();
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  out_ += buf;
  return *this;
}

JsonWriter& JsonWriter::value(int64_t v) {
  before_value();
  out_ += std::to_string(v);
  return *this;
}

JsonWriter& JsonWriter::value(uint64_t v) {
  before_value();
  out_ += std::to_string(v);
  return *this;
}

JsonWriter& JsonWriter::value(bool v) {
  before_value();
  out_ += v ? "true" : "false";
  return *this;
}

JsonWriter& JsonWriter::value(const std::string& v) {
  before_value();
  out_ += quote(v);
  return *this;
}

JsonWriter& JsonWriter::null() {
  before_value();
  out_ += "null";
  return *this;
}

std::string JsonWriter::str() const {
  if (!stack_.empty() || after_key_) throw std::logic_error("JsonWriter: document not complete");
  return out_ + "\n";
}

// ------------------------------------------------------------------ parser
class JsonParser {
 public:
  explicit JsonParser(const std::string& text) : t_(text) {}

  JsonValue document() {
    JsonValue v = value(0);
    skip();
    if (pos_ != t_.size()) fail("trailing characters");
    return v;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("JSON: " + what + " at offset " + std::to_string(pos_));
  }
  void skip() {
    while (pos_ < t_.size() && (t_[pos_] == ' ' || t_[pos_] == '\n' || t_[pos_] == '\r' || t_[pos_] == '\t')) ++pos_;
  }
  bool consume(const char* word) {
    const std::string w(word);
    if (t_.compare(pos_, w.size(), w) == 0) {
      pos_ += w.size();
      return true;
    }
    return false;
  }
  void expect(char c) {
    skip();
    if (pos_ >= t_.size() || t_[pos_] != c) fail(std::string("expected '") + c + "'");
    ++pos_;
  }

  std::string string_literal() {
    expect('"');
    std::string s;
    while (true) {
      if (pos_ >= t_.size()) fail("unterminated string");
      const char c = t_[pos_++];
      if (c == '"') return s;
      if (c != '\\') {
        s += c;
        continue;
      }
      if (pos_ >= t_.size()) fail("unterminated escape");
      const char e = t_[pos_++];
      switch (e) {
        case '"': s += '"'; break;
        case '\\': s += '\\'; break;
        case '/': s += '/'; break;
        case 'b': s += '\b'; break;
        case 'f': s += '\f'; break;
        case 'n': s += '\n'; break;
        case 'r': s += '\r'; break;
        case 't': s += '\t'; break;
        case 'u': {
          if (pos_ + 4 > t_.size()) fail("short \\u escape");
          const unsigned long cp = std::strtoul(t_.substr(pos_, 4).c_str(), nullptr, 16);
          pos_ += 4;
          if (cp < 0x80) {
            s += static_cast<char>(cp);
          } else if (cp < 0x800) {
            s += static_cast<char>(0xC0 | (cp >> 6));
            s += static_cast<char>(0x80 | (cp & 0x3F));
          } else {
            s += static_cast<char>(0xE0 | (cp >> 12));
            s += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
            s += static_cast<char>(0x80 | (cp & 0x3F));
          }
          break;
        }
        default: fail("bad escape");
      }
    }
  }

  JsonValue value(int depth) {
    if (depth > 64) fail("nesting too deep");
    skip();
    if (pos_ >= t_.size()) fail("unexpected end");
    JsonValue v;
    const char c = t_[pos_];
    if (c == '{') {
      ++pos_;
      v.kind_ = JsonValue::Kind::kObject;
      skip();
      if (pos_ < t_.size() && t_[pos_] == '}') {
        ++pos_;
        return v;
      }
      while (true) {
        skip();
        std::string k = string_literal();
        expect(':');
        v.object_.emplace_back(std::move(k), value(depth + 1));
        skip();
        if (pos_ < t_.size() && t_[pos_] == ',') {
          ++pos_;
          continue;
        }
        expect('}');
        return v;
      }
    }
    if (c == '[') {
      ++pos_;
      v.kind_ = JsonValue::Kind::kArray;
      skip();
      if (pos_ < t_.size() && t_[pos_] == ']') {
        ++pos_;
        return v;
      }
      while (true) {
        v.array_.push_back(value(depth + 1));
        skip();
        if (pos_ < t_.size() && t_[pos_] == ',') {
          ++pos_;
          continue;
        }
        expect(']');
        return v;
      }
    }
    if (c == '"') {
      v.kind_ = JsonValue::Kind::kString;
      v.string_ = string_literal();
      return v;
    }
    if (consume("true")) {
      v.kind_ = JsonValue::Kind::kBool;
      v.bool_ = true;
      return v;
    }
    if (consume("false")) {
      v.kind_ = JsonValue::Kind::kBool;
      return v;
    }
    if (consume("null")) return v;
    const char* begin = t_.c_str() + pos_;
    char* end = nullptr;
    const double d = std::strtod(begin, &end);
    if (end == begin) fail("unexpected character");
    pos_ += static_cast<std::size_t>(end - begin);
    v.kind_ = JsonValue::Kind::kNumber;
    v.number_ = d;
    return v;
  }

  const std::string& t_;
  std::size_t pos_{0};
};

JsonValue JsonValue::parse(const std::string& text) { return JsonParser(text).document(); }

bool JsonValue::has(const std::string& key) const {
  if (kind_ != Kind::kObject) return false;
  for (const auto& kv : object_) {
    if (kv.first == key) return true;
  }
  return false;
}

const JsonValue& JsonValue::at(const std::string& key) const {
  if (kind_ != Kind::kObject) throw std::runtime_error("JSON: '" + key + "' looked up in a non-object");
  for (const auto& kv : object_) {
    if (kv.first == key) return kv.second;
  }
  throw std::runtime_error("JSON: no key '" + key + "'");
}

const JsonValue& JsonValue::at(std::size_t index) const {
  if (kind_ != Kind::kArray || index >= array_.size()) {
    throw std::runtime_error("JSON: index " + std::to_string(index) + " out of range");
  }
  return array_[index];
}

std::size_t JsonValue::size() const {
  return kind_ == Kind::kArray ? array_.size() : kind_ == Kind::kObject ? object_.size() : 0;
}

double JsonValue::number() const {
  if (kind_ == Kind::kNull) return std::nan("");
  if (kind_ != Kind::kNumber) throw std::runtime_error("JSON: not a number");
  return number_;
}

bool JsonValue::boolean() const {
  if (kind_ != Kind::kBool) throw std::runtime_error("JSON: not a boolean");
  return bool_;
}

const std::string& JsonValue::string() const {
  if (kind_ != Kind::kString) throw std::runtime_error("JSON: not a string");
  return string_;
}

}  // namespace eval
}  // namespace vimot

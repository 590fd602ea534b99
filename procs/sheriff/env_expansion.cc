#include "procs/sheriff/env_expansion.h"

#include <cctype>
#include <cstdlib>
#include <stdexcept>

namespace vimot::sheriff {

namespace {

bool IsNameStart(char c) {
  return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}

bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

std::string Quoted(std::string_view text) {
  return "\"" + std::string(text) + "\"";
}

}  // namespace

std::optional<std::string> LookupProcessEnvironment(const std::string& name) {
  const char* value = std::getenv(name.c_str());
  if (value == nullptr) return std::nullopt;
  return std::string(value);
}

std::string ExpandEnvironmentVariables(std::string_view text,
                                       const EnvironmentLookup& lookup) {
  if (!lookup) {
    throw std::invalid_argument(
        "ExpandEnvironmentVariables: the lookup function is empty");
  }
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const char c = text[i];
    if (c != '$' || i + 1 == text.size()) {
      out.push_back(c);
      ++i;
      continue;
    }
    const char next = text[i + 1];
    if (next == '$') {
      out.push_back('$');
      i += 2;
      continue;
    }
    std::string name;
    std::size_t end = 0;  // Index one past the reference.
    if (next == '{') {
      const std::size_t close = text.find('}', i + 2);
      if (close == std::string_view::npos) {
        throw std::runtime_error("unterminated '${' at character " +
                                 std::to_string(i + 1) + " of " +
                                 Quoted(text));
      }
      name = std::string(text.substr(i + 2, close - (i + 2)));
      bool valid = !name.empty() && IsNameStart(name[0]);
      for (const char n : name) valid = valid && IsNameChar(n);
      if (!valid) {
        throw std::runtime_error("'${" + name +
                                 "}' is not a valid environment variable "
                                 "reference (expected ${NAME} with NAME made "
                                 "of letters, digits and '_') in " +
                                 Quoted(text));
      }
      end = close + 1;
    } else if (IsNameStart(next)) {
      end = i + 1;
      while (end < text.size() && IsNameChar(text[end])) ++end;
      name = std::string(text.substr(i + 1, end - (i + 1)));
    } else {
      // `$1`, `$?`, `$(...)`: shell syntax that is not ours to expand.
      out.push_back('$');
      ++i;
      continue;
    }
    const std::optional<std::string> value = lookup(name);
    if (!value) {
      throw std::runtime_error("undefined environment variable '" + name +
                               "' in " + Quoted(text) +
                               " (write $$ for a '$' meant for the shell)");
    }
    out += *value;
    i = end;
  }
  return out;
}

}  // namespace vimot::sheriff

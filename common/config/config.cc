#include "common/config/config.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace vimot {

namespace {

std::vector<std::string> split_key(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  return parts;
}

// yaml-cpp only knows "%YAML 1.x"; ASL files start with "%YAML:1.0".
std::string strip_asl_header(const std::string& text) {
  if (text.rfind("%YAML:", 0) != 0) return text;
  const auto eol = text.find('\n');
  // Keep the line count so parse errors point at the right line.
  return eol == std::string::npos ? std::string() : "\n" + text.substr(eol + 1);
}

// Flow style for `n` and everything in it (a parsed node keeps its own).
void set_flow_style(YAML::Node n) {
  if (!n.IsMap() && !n.IsSequence()) return;
  n.SetStyle(YAML::EmitterStyle::Flow);
  for (auto it = n.begin(); it != n.end(); ++it) set_flow_style(n.IsMap() ? it->second : *it);
}

// The value of a node for an error message: a scalar as written, anything
// else on one line in YAML flow style, cut short.
std::string describe(const YAML::Node& n) {
  std::string text;
  if (n.IsScalar()) {
    text = n.Scalar();
  } else {
    const YAML::Node copy = YAML::Clone(n);
    set_flow_style(copy);
    YAML::Emitter out;
    out << copy;
    text = out.c_str();
  }
  constexpr std::size_t kMax = 60;
  return text.size() > kMax ? text.substr(0, kMax) + "..." : text;
}

// yaml-cpp keeps every entry of a map, so a repeated key would be read as
// its first value and the second silently ignored.
void reject_duplicate_keys(const YAML::Node& node, const std::string& prefix, const std::string& source) {
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) reject_duplicate_keys(node[i], prefix, source);
    return;
  }
  if (!node.IsMap()) return;
  std::set<std::string> seen;
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const std::string path = prefix.empty() ? key : prefix + "." + key;
    if (!seen.insert(key).second) {
      throw ConfigError("config '" + source + "': key '" + path + "' is repeated (line " +
                        std::to_string(kv.first.Mark().line + 1) + ", value '" + describe(kv.second) +
                        "'); each key may appear once");
    }
    reject_duplicate_keys(kv.second, path, source);
  }
}

}  // namespace

Config::Config() : root_(YAML::NodeType::Map), source_("<empty>") {}

Config::Config(YAML::Node root, std::string source, std::string prefix)
    : root_(std::move(root)), source_(std::move(source)), prefix_(std::move(prefix)) {}

Config Config::load_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw ConfigError("config '" + path + "': is a directory, not a YAML file");
  }
  std::ifstream in(path);
  if (!in) throw ConfigError("config '" + path + "': cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  Config config = from_string(buffer.str(), path);
  // An empty file would fail later on its first required key, which hides
  // the cause (e.g. "cameras.cam0: missing").
  if (config.root_.size() == 0) throw ConfigError("config '" + path + "': is empty (no keys)");
  return config;
}

Config Config::from_string(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(strip_asl_header(text));
  } catch (const YAML::Exception& e) {
    throw ConfigError("config '" + source + "': malformed YAML at line " +
                      std::to_string(e.mark.line + 1) + ", column " + std::to_string(e.mark.column + 1) +
                      ": " + e.msg);
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw ConfigError("config '" + source + "': top level must be a map of keys");
  reject_duplicate_keys(root, "", source);
  return Config(root, source, "");
}

std::string Config::full_key(const std::string& key) const {
  return prefix_.empty() ? key : prefix_ + "." + key;
}

void Config::fail(const std::string& key, const std::string& what) const {
  throw ConfigError("config '" + source_ + "': key '" + full_key(key) + "' " + what);
}

YAML::Node Config::find(const std::string& key) const {
  // YAML::Node assignment rebinds, so walk with fresh nodes, never operator=.
  std::vector<YAML::Node> path{root_};
  for (const std::string& part : split_key(key)) {
    const YAML::Node& cur = path.back();
    if (!cur.IsMap() || !cur[part]) return YAML::Node(YAML::NodeType::Undefined);
    path.push_back(cur[part]);
  }
  return path.back();
}

YAML::Node Config::require(const std::string& key) const {
  YAML::Node n = find(key);
  if (!n.IsDefined() || n.IsNull()) fail(key, "is missing");
  return n;
}

std::string Config::resolve_path(const std::string& path) const {
  if (path.empty() || path[0] == '/') return path;
  const auto slash = source_.find_last_of('/');
  return (slash == std::string::npos ? std::string(".") : source_.substr(0, slash)) + "/" + path;
}

bool Config::has(const std::string& key) const {
  const YAML::Node n = find(key);
  return n.IsDefined() && !n.IsNull();
}

template <>
double Config::get<double>(const std::string& key) const {
  const YAML::Node n = require(key);
  double v = 0.0;
  if (!n.IsScalar() || !YAML::convert<double>::decode(n, v)) fail(key, "must be a number");
  if (!std::isfinite(v)) fail(key, "must be finite, got '" + n.Scalar() + "'");
  return v;
}

template <>
int64_t Config::get<int64_t>(const std::string& key) const {
  const YAML::Node n = require(key);
  int64_t v = 0;
  if (!n.IsScalar() || !YAML::convert<int64_t>::decode(n, v)) fail(key, "must be an integer");
  return v;
}

template <>
int Config::get<int>(const std::string& key) const {
  const YAML::Node n = require(key);
  int v = 0;
  if (!n.IsScalar() || !YAML::convert<int>::decode(n, v)) fail(key, "must be an integer");
  return v;
}

template <>
bool Config::get<bool>(const std::string& key) const {
  const YAML::Node n = require(key);
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) fail(key, "must be true or false");
  return v;
}

template <>
std::string Config::get<std::string>(const std::string& key) const {
  const YAML::Node n = require(key);
  if (!n.IsScalar()) fail(key, "must be a string");
  return n.Scalar();
}

std::vector<double> Config::get_vector(const std::string& key, int expected_size) const {
  const YAML::Node n = require(key);
  if (!n.IsSequence()) fail(key, "must be a list of numbers");
  if (expected_size >= 0 && static_cast<int>(n.size()) != expected_size) {
    fail(key, "must have " + std::to_string(expected_size) + " elements, has " + std::to_string(n.size()));
  }
  std::vector<double> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    double v = 0.0;
    if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v) || !std::isfinite(v)) {
      fail(key, "element " + std::to_string(i) + " must be a finite number");
    }
    out.push_back(v);
  }
  return out;
}

Eigen::MatrixXd Config::get_matrix(const std::string& key, int rows, int cols) const {
  const YAML::Node n = require(key);
  std::vector<double> data;
  if (n.IsMap()) {
    const Config m = sub(key);
    if (m.get<int>("rows") != rows || m.get<int>("cols") != cols) {
      fail(key, "must be " + std::to_string(rows) + "x" + std::to_string(cols));
    }
    data = m.get_vector("data", rows * cols);
  } else {
    data = get_vector(key, rows * cols);
  }
  Eigen::MatrixXd out(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) out(r, c) = data[static_cast<std::size_t>(r * cols + c)];
  return out;
}

Config Config::sub(const std::string& key) const {
  const YAML::Node n = require(key);
  if (!n.IsMap()) fail(key, "must be a map of keys");
  return Config(n, source_, full_key(key));
}

std::vector<std::string> Config::keys() const {
  std::vector<std::string> out;
  if (!root_.IsMap()) return out;
  for (const auto& kv : root_) out.push_back(kv.first.as<std::string>());
  return out;
}

void Config::check_keys(const std::string& section, const std::vector<std::string>& known) const {
  if (!section.empty() && !has(section)) return;
  const YAML::Node node = section.empty() ? root_ : find(section);
  if (!node.IsMap()) fail(section, "must be a map of keys");
  const std::string prefix = section.empty() ? "" : section + ".";
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    fail(prefix + key, "(value '" + describe(kv.second) + "') is unknown (known keys: " + list + ")");
  }
}

}  // namespace vimot

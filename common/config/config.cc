#include "common/config/config.h"

#include <cmath>
#include <fstream>
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

}  // namespace

Config::Config() : root_(YAML::NodeType::Map), source_("<empty>") {}

Config::Config(YAML::Node root, std::string source, std::string prefix)
    : root_(std::move(root)), source_(std::move(source)), prefix_(std::move(prefix)) {}

Config Config::load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError("config '" + path + "': cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return from_string(buffer.str(), path);
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

}  // namespace vimot

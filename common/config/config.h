#pragma once
// YAML configuration with errors that name the file and the full key.
//
// Keys are dotted paths ("imu.gyroscope_noise_density"). Every getter checks
// presence, type and finiteness, and every options reader rejects keys it
// does not know (check_keys), so a process refuses a bad config at start
// instead of running on a silent default. A key repeated in one map is an
// error at load. Files in the ASL/EuRoC style (first line "%YAML:1.0", which
// yaml-cpp rejects) are accepted.

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace vimot {

/// Thrown for every configuration problem; what() names the source and key.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Config {
 public:
  /// An empty configuration (every get() fails, every get_or() defaults).
  Config();

  /// Loads a YAML file; throws ConfigError if missing, a directory, empty
  /// (nothing but comments), malformed or with a key repeated in one map.
  static Config load_file(const std::string& path);

  /// Parses YAML text; `source` names it in error messages.
  static Config from_string(const std::string& text, const std::string& source = "<string>");

  bool has(const std::string& key) const;

  /// Scalars: double (finite only), int, int64_t, bool, std::string.
  template <typename T>
  T get(const std::string& key) const;

  template <typename T>
  T get_or(const std::string& key, const T& fallback) const {
    return has(key) ? get<T>(key) : fallback;
  }

  /// A sequence of finite numbers; `expected_size` < 0 accepts any length.
  std::vector<double> get_vector(const std::string& key, int expected_size = -1) const;

  /// A fixed-size vector, e.g. get_vec<3>("p_TinG").
  template <int N>
  Eigen::Matrix<double, N, 1> get_vec(const std::string& key) const {
    const std::vector<double> v = get_vector(key, N);
    return Eigen::Map<const Eigen::Matrix<double, N, 1>>(v.data());
  }

  /// A rows x cols matrix written either as {rows, cols, data: [...]} (ASL
  /// style, row-major) or as a flat row-major list of rows*cols numbers.
  Eigen::MatrixXd get_matrix(const std::string& key, int rows, int cols) const;

  /// The sub-tree at `key` as its own Config (errors keep the full path).
  Config sub(const std::string& key) const;

  /// Top-level keys of a map node (empty for anything else).
  std::vector<std::string> keys() const;

  /// The one unknown-key check of every options reader: each key of the map
  /// at `section` ("" = this config's top level; an absent section passes)
  /// must be in `known`, else ConfigError naming the file, the full key
  /// path, its value and the known keys (a misspelt option must not keep
  /// its default silently).
  void check_keys(const std::string& section, const std::vector<std::string>& known) const;

  const std::string& source() const { return source_; }

  /// A path written in this config, relative to the config file's folder
  /// unless absolute (so a config can name its calibration file portably).
  std::string resolve_path(const std::string& path) const;

  /// The key's full dotted path from the file's root ("cameras.cam0.T_BS").
  std::string full_key(const std::string& key) const;

  /// Throws ConfigError "config '<file>': key '<full key>' <what>", for
  /// checks a caller makes beyond type and presence.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

 private:
  Config(YAML::Node root, std::string source, std::string prefix);
  YAML::Node find(const std::string& key) const;       // undefined node if absent
  YAML::Node require(const std::string& key) const;    // throws if absent

  YAML::Node root_;
  std::string source_;
  std::string prefix_;
};

}  // namespace vimot

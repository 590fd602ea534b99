// Configuration loading: values read back as written, and every kind of bad
// input fails with a message that names the file and the full key.
#include <catch2/catch.hpp>

#include <cstdio>
#include <fstream>

#include "common/config/config.h"
#include "common/time/utime.h"

using vimot::Config;
using vimot::ConfigError;

namespace {
const char* kYaml = R"(
imu:
  rate_hz: 200
  gyroscope_noise_density: 1.6968e-04
  enabled: true
  name: adis16448
  p_IinG: [1.0, 2.0, 3.0]
T_BS:
  rows: 2
  cols: 2
  data: [1, 2, 3, 4]
flat: [5, 6, 7, 8]
bad_number: abc
nan_value: .nan
)";

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no exception>";
}
}  // namespace

TEST_CASE("config values read back as written") {
  const Config c = Config::from_string(kYaml, "test.yaml");
  CHECK(c.get<int>("imu.rate_hz") == 200);
  CHECK(c.get<double>("imu.gyroscope_noise_density") == 1.6968e-04);
  CHECK(c.get<bool>("imu.enabled"));
  CHECK(c.get<std::string>("imu.name") == "adis16448");
  CHECK(c.get_vec<3>("imu.p_IinG") == Eigen::Vector3d(1, 2, 3));
  const Eigen::MatrixXd m = c.get_matrix("T_BS", 2, 2);
  CHECK(m(0, 1) == 2.0);
  CHECK(m(1, 0) == 3.0);
  CHECK(c.get_matrix("flat", 2, 2)(1, 1) == 8.0);
  CHECK(c.get_or<double>("imu.missing", 4.5) == 4.5);
  CHECK(c.sub("imu").get<int>("rate_hz") == 200);
}

TEST_CASE("a missing key fails with that key's full name and the file") {
  const Config c = Config::from_string(kYaml, "test.yaml");
  const std::string msg = message_of([&] { c.get<double>("imu.accelerometer_noise_density"); });
  CHECK(msg.find("'imu.accelerometer_noise_density'") != std::string::npos);
  CHECK(msg.find("missing") != std::string::npos);
  CHECK(msg.find("test.yaml") != std::string::npos);
  // Through a sub-tree the full path is kept.
  const std::string sub_msg = message_of([&] { c.sub("imu").get<int>("rate"); });
  CHECK(sub_msg.find("'imu.rate'") != std::string::npos);
}

TEST_CASE("bad values are refused with the key named") {
  const Config c = Config::from_string(kYaml, "test.yaml");
  CHECK(message_of([&] { c.get<double>("bad_number"); }).find("'bad_number' must be a number") != std::string::npos);
  CHECK(message_of([&] { c.get<double>("nan_value"); }).find("finite") != std::string::npos);
  CHECK(message_of([&] { c.get_vec<2>("imu.p_IinG"); }).find("must have 2 elements") != std::string::npos);
  CHECK(message_of([&] { c.get_matrix("T_BS", 3, 3); }).find("'T_BS' must be 3x3") != std::string::npos);
  CHECK(message_of([&] { c.get<int>("imu.name"); }).find("integer") != std::string::npos);
}

TEST_CASE("missing and malformed files are reported, ASL headers accepted") {
  CHECK(message_of([] { Config::load_file("/nonexistent/vimot.yaml"); }).find("cannot open") != std::string::npos);
  const std::string malformed = message_of([] { Config::from_string("a: [1, 2\nb: 3\n", "broken.yaml"); });
  CHECK(malformed.find("broken.yaml") != std::string::npos);
  CHECK(malformed.find("line") != std::string::npos);
  const Config asl = Config::from_string("%YAML:1.0\nrate_hz: 20\n", "sensor.yaml");
  CHECK(asl.get<int>("rate_hz") == 20);
}

TEST_CASE("a directory or an empty file as a config says so") {
  const std::string dir = message_of([] { Config::load_file("/tmp"); });
  CHECK(dir.find("'/tmp'") != std::string::npos);
  CHECK(dir.find("is a directory") != std::string::npos);
  const std::string path = "/tmp/vimot_config_test_empty.yaml";
  std::ofstream(path) << "# only a comment\n";
  const std::string empty = message_of([&] { Config::load_file(path); });
  std::remove(path.c_str());
  CHECK(empty.find(path) != std::string::npos);
  CHECK(empty.find("is empty") != std::string::npos);
}

TEST_CASE("a key repeated in one map is refused with its path, line and value") {
  const std::string top = message_of([] { Config::from_string("a: 1\nb: 2\na: 3\n", "dup.yaml"); });
  CHECK(top.find("config 'dup.yaml': key 'a' is repeated (line 3, value '3')") != std::string::npos);
  const std::string nested =
      message_of([] { Config::from_string("estimator:\n  triangulation: {min_depth: 1, min_depth: 2}\n", "d.yaml"); });
  CHECK(nested.find("key 'estimator.triangulation.min_depth' is repeated") != std::string::npos);
  CHECK(nested.find("value '2'") != std::string::npos);
  // The same key in different maps is fine.
  CHECK_NOTHROW(Config::from_string("a: {x: 1}\nb: {x: 2}\n", "ok.yaml"));
}

TEST_CASE("check_keys refuses an unknown key naming file, full path and value") {
  const Config c = Config::from_string("estimator:\n  num_clonez: 5\n  init: {sigma_p: 1}\nchannelz: {imu: IMU}\n",
                                       "v.yaml");
  const std::string nested = message_of([&] { c.check_keys("estimator", {"num_clones", "init"}); });
  CHECK(nested.find("config 'v.yaml': key 'estimator.num_clonez' (value '5') is unknown "
                    "(known keys: num_clones, init)") != std::string::npos);
  const std::string section = message_of([&] { c.check_keys("", {"estimator", "channels"}); });
  CHECK(section.find("key 'channelz' (value '{imu: IMU}') is unknown") != std::string::npos);
  // Through a sub-tree the full path is kept; an absent section passes.
  const std::string sub = message_of([&] { c.sub("estimator").check_keys("init", {"sigma_v"}); });
  CHECK(sub.find("key 'estimator.init.sigma_p' (value '1')") != std::string::npos);
  CHECK_NOTHROW(c.check_keys("absent", {}));
  CHECK_NOTHROW(c.check_keys("estimator", {"num_clonez", "init"}));
}

TEST_CASE("utime conversions round to the nearest microsecond") {
  CHECK(vimot::seconds_to_utime(1.0) == 1000000);
  CHECK(vimot::seconds_to_utime(0.005) == 5000);
  // 0.1 * 3 is 0.30000000000000004: rounding, not truncation, gives 300000.
  CHECK(vimot::seconds_to_utime(0.1 * 3) == 300000);
  CHECK(vimot::seconds_to_utime(2.9999999) == 3000000);
  CHECK(vimot::utime_to_seconds(1500000) == 1.5);
}

TEST_CASE("paths in a config resolve relative to the config file") {
  const Config c = Config::from_string("a: 1\n", "/etc/vimot/vins.yaml");
  CHECK(c.resolve_path("euroc_stereo.yaml") == "/etc/vimot/euroc_stereo.yaml");
  CHECK(c.resolve_path("/abs/file.yaml") == "/abs/file.yaml");
  CHECK(Config::from_string("a: 1\n", "local.yaml").resolve_path("x.yaml") == "./x.yaml");
}

// config/imu_mip.yaml reads into the driver options; bad values are refused
// with the file and key named.
#include <catch2/catch.hpp>

#include "drivers/imu_mip/imu_mip_config.h"

using vimot::Config;
using vimot::ConfigError;
using vimot::mip::imu_mip_config_from;

TEST_CASE("config/imu_mip.yaml gives the documented options") {
  const auto c = imu_mip_config_from(Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/imu_mip.yaml"));
  CHECK(c.port == "/dev/ttyACM0");
  CHECK(c.baud == 115200);
  CHECK_FALSE(c.raw_tty);
  CHECK(c.driver.rate_hz == 200.0);
  CHECK(c.driver.timestamp_field == vimot::mip::kFieldGpsTimestamp);
  CHECK(c.driver.command_tries == 3);
  CHECK(c.driver.time.max_drift == 2e-4);
}

TEST_CASE("Bad imu_mip settings name the key") {
  auto fails = [](const std::string& yaml, const std::string& key) {
    CHECK_THROWS_WITH(imu_mip_config_from(Config::from_string(yaml, "test.yaml")), Catch::Contains(key));
  };
  fails("device: {baud: 115200}", "device.port");
  fails("device: {port: /dev/x, interface: usb}", "device.interface");
  fails("device: {port: /dev/x, rate: 0}", "device.rate");
  fails("device: {port: /dev/x, timestamp: internal}", "device.timestamp");
  fails("device: {port: /dev/x, command_tries: 0}", "device.command_tries");
  fails("device: {port: /dev/x}\ntime_mapping: {relock_after: -1}", "time_mapping.relock_after");
  const auto tty = imu_mip_config_from(Config::from_string("device: {port: /dev/pts/3, interface: tty, timestamp: reference}"));
  CHECK(tty.raw_tty);
  CHECK(tty.driver.timestamp_field == vimot::mip::kFieldReferenceTime);
}

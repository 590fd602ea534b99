#pragma once
// vimot-imu-mip's configuration (config/imu_mip.yaml), read in one place.

#include <string>

#include "common/config/config.h"
#include "drivers/imu_mip/byte_stream.h"
#include "drivers/imu_mip/imu_mip_driver.h"

namespace vimot::mip {

struct ImuMipConfig {
  std::string port;                 // device path, e.g. /dev/ttyACM0
  int baud{115200};
  bool raw_tty{false};              // interface: tty (raw fd) instead of libserialport
  ImuMipOptions driver;
};

/// Reads `device.*` and `time_mapping.*`; throws ConfigError naming the key.
ImuMipConfig imu_mip_config_from(const Config& config);

/// The opener the config asks for (libserialport, or a raw tty fd).
StreamOpener stream_opener(const ImuMipConfig& config);

}  // namespace vimot::mip

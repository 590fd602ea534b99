#pragma once
// vimot-camera's configuration (config/camera.yaml), read and checked in
// one place.

#include <functional>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "drivers/camera/camera_driver.h"
#include "drivers/camera/video_source.h"

namespace vimot::camera {

struct CameraConfig {
  std::vector<std::string> sources;  // left[, right]: "/dev/videoN", an index, a file or "dir/frame_%04d.png"
  DeviceRequest request;             // asked of V4L2 devices
  int stall_timeout_s{2};            // s a device read waits for a frame before it counts as a stall
  CameraOptions driver;
};

/// Reads mode, sources, image, timing, reopen (unknown keys refused by
/// Config::check_keys); throws ConfigError naming the file and key.
CameraConfig camera_config_from(const Config& config);

/// The opener of camera `index` (0 = left): a device is asked for the
/// configured size, rate and exposure, and what it accepted goes to `log`
/// on every open. File paths in the config are relative to its folder.
SourceOpener source_opener(const CameraConfig& config, std::size_t index,
                           const std::function<void(const std::string&)>& log);

}  // namespace vimot::camera

#include "drivers/imu_mip/device_time_mapper.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace vimot {

DeviceTimeMapper::DeviceTimeMapper(const DeviceTimeMapperOptions& options) : options_(options) {
  if (!(options.max_drift >= 0.0) || !(options.relock_threshold > 0.0) || !(options.relock_after > 0.0)) {
    throw std::invalid_argument("DeviceTimeMapper: max_drift must be >= 0, relock_threshold and relock_after > 0 (got " +
                                std::to_string(options.max_drift) + ", " + std::to_string(options.relock_threshold) +
                                ", " + std::to_string(options.relock_after) + ")");
  }
}

void DeviceTimeMapper::reset() {
  locked_ = false;
  late_since_us_.reset();
}

void DeviceTimeMapper::lock(double device_us, double offset_us) {
  locked_ = true;
  offset_us_ = offset_us;
  last_device_us_ = device_us;
  late_since_us_.reset();
}

int64_t DeviceTimeMapper::map(double device_time, int64_t arrival_utime) {
  if (!std::isfinite(device_time)) throw std::invalid_argument("DeviceTimeMapper: non-finite device time");
  const double device_us = device_time * 1e6;
  const double offset_us = static_cast<double>(arrival_utime) - device_us;

  if (!locked_) {
    lock(device_us, offset_us);
  } else if (device_us <= last_device_us_) {
    ++relocks_;  // the device clock restarted
    lock(device_us, offset_us);
  } else {
    offset_us_ = std::min(offset_us_ + options_.max_drift * (device_us - last_device_us_), offset_us);
    last_device_us_ = device_us;
    if (offset_us - offset_us_ > options_.relock_threshold * 1e6) {
      if (!late_since_us_) {
        late_since_us_ = device_us;
        late_min_offset_us_ = offset_us;
      }
      late_min_offset_us_ = std::min(late_min_offset_us_, offset_us);
      if (device_us - *late_since_us_ >= options_.relock_after * 1e6) {
        ++relocks_;
        lock(device_us, late_min_offset_us_);
      }
    } else {
      late_since_us_.reset();
    }
  }

  int64_t out = static_cast<int64_t>(std::llround(device_us + offset_us_));
  if (last_output_) out = std::max(out, *last_output_ + 1);
  last_output_ = out;
  return out;
}

}  // namespace vimot

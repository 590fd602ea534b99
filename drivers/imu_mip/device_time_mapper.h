#pragma once
// Maps the device's sample clock onto the host clock.
//
// Model: a sample taken at device time d reaches the host at
//   arrival = d + offset(t) + latency,   latency >= L_min, jittery, sometimes huge
// with offset drifting slowly (the two crystals' rate difference, tens of
// ppm). The filter tracks the lower envelope of (arrival - d): it drops to
// any smaller value at once (a sample that was quicker) and rises at most at
// `max_drift` seconds per second, so delayed samples never pull it up and a
// host clock running faster than the device is still followed. The mapped
// time d + offset_estimate then carries the device's sample spacing, not the
// transport's jitter, with the constant L_min (unobservable without
// hardware sync) as its only bias; it is never later than the arrival time.
//
// Output never goes backwards: each mapped time is at least the previous one
// plus 1 µs. The device clock restarting (time going backwards, e.g. after a
// power cycle) or a persistent step (every sample later than the envelope by
// more than `relock_threshold` for `relock_after` seconds, e.g. the host
// clock stepped forward) re-locks the envelope.

#include <cstdint>
#include <optional>

namespace vimot {

struct DeviceTimeMapperOptions {
  double max_drift{2e-4};         // s/s: fastest the offset may rise (clock rate difference bound)
  double relock_threshold{0.05};  // s: apparent latency above this counts towards a re-lock
  double relock_after{1.0};       // s of device time with every sample above the threshold
};

class DeviceTimeMapper {
 public:
  explicit DeviceTimeMapper(const DeviceTimeMapperOptions& options = {});

  /// Host time (µs) of a sample with device time `device_time` (s) that
  /// arrived at host time `arrival_utime` (µs).
  int64_t map(double device_time, int64_t arrival_utime);

  /// Forgets the device clock (after a reconnect); the no-going-back
  /// guarantee still holds across it.
  void reset();

  /// Re-locks so far (device restarts and steps); for the counters.
  int64_t relocks() const { return relocks_; }

 private:
  void lock(double device_us, double offset_us);

  DeviceTimeMapperOptions options_;
  bool locked_{false};
  double last_device_us_{0.0};
  double offset_us_{0.0};  // lower envelope of arrival - device
  // Persistent-step detection: start of the run of late samples, and the
  // smallest offset seen in it (the re-lock value).
  std::optional<double> late_since_us_;
  double late_min_offset_us_{0.0};
  std::optional<int64_t> last_output_;
  int64_t relocks_{0};
};

}  // namespace vimot

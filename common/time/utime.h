#pragma once
// Time on vimot messages: int64_t microseconds ("utime"). Estimation uses
// message utimes only; the wall clock is for heartbeats and logs.

#include <cmath>
#include <cstdint>

namespace vimot {

constexpr int64_t kMicrosPerSecond = 1000000;

/// Seconds -> utime, rounded to the nearest microsecond (not truncated, so a
/// 200 Hz clock built from doubles does not drift by 1 µs steps).
inline int64_t seconds_to_utime(double seconds) {
  return static_cast<int64_t>(std::llround(seconds * static_cast<double>(kMicrosPerSecond)));
}

inline double utime_to_seconds(int64_t utime) {
  return static_cast<double>(utime) / static_cast<double>(kMicrosPerSecond);
}

/// Wall-clock time now, in microseconds since the epoch (monitoring only).
int64_t wall_clock_utime();

/// CPU time of the calling thread, ms (per-frame cost figures: unlike wall
/// time it does not count waiting for a core on a loaded machine).
double thread_cpu_ms();

}  // namespace vimot

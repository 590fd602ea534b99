#pragma once
// CPU and memory figures from /proc, for procman's deputy info.

#include <sys/types.h>

#include <cstdint>
#include <optional>

namespace vimot::deputy {

/// /proc/stat and /proc/meminfo.
struct SystemStats {
  /// Jiffies summed over all CPUs.
  uint64_t busy_jiffies{0};
  uint64_t total_jiffies{0};
  int64_t mem_total_bytes{0};
  int64_t mem_free_bytes{0};
  int64_t swap_total_bytes{0};
  int64_t swap_free_bytes{0};
};

/// /proc/<pid>/stat.
struct ProcessStats {
  /// utime + stime.
  uint64_t cpu_jiffies{0};
  int64_t vsize_bytes{0};
  int64_t rss_bytes{0};
};

/// nullopt when /proc cannot be read or parsed.
std::optional<SystemStats> ReadSystemStats();
/// nullopt when the process is gone (or /proc is malformed).
std::optional<ProcessStats> ReadProcessStats(pid_t pid);

/// Fraction of `total` spent in `used` between two samples, in [0, 1]; 0
/// when no time passed or the counters went backwards.
float JiffyFraction(uint64_t used_before, uint64_t used_after,
                    uint64_t total_before, uint64_t total_after);

}  // namespace vimot::deputy

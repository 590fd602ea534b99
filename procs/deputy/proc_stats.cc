#include "procs/deputy/proc_stats.h"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <string>

namespace vimot::deputy {

std::optional<SystemStats> ReadSystemStats() {
  SystemStats s;
  std::ifstream stat("/proc/stat");
  std::string cpu;
  uint64_t user = 0, nice = 0, system = 0, idle = 0;
  if (!(stat >> cpu >> user >> nice >> system >> idle) || cpu != "cpu") {
    return std::nullopt;
  }
  // procman's load: user + nice + system over those plus idle (iowait and
  // irq time are left out of both).
  s.busy_jiffies = user + nice + system;
  s.total_jiffies = s.busy_jiffies + idle;

  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  int64_t kib = 0;
  std::string unit;
  std::string line;
  while (std::getline(meminfo, line)) {
    std::istringstream fields(line);
    if (!(fields >> key >> kib)) continue;
    const int64_t bytes = kib * 1024;
    if (key == "MemTotal:") s.mem_total_bytes = bytes;
    if (key == "MemFree:") s.mem_free_bytes = bytes;
    if (key == "SwapTotal:") s.swap_total_bytes = bytes;
    if (key == "SwapFree:") s.swap_free_bytes = bytes;
  }
  return s;
}

std::optional<ProcessStats> ReadProcessStats(pid_t pid) {
  std::ifstream file("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(file, line)) return std::nullopt;
  // The command name (field 2) is in parentheses and may hold spaces and
  // ')': the numeric fields start after the last ')'.
  const std::size_t close = line.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(line.substr(close + 1));
  // Fields 3.. : state ppid pgrp session tty_nr tpgid flags minflt cminflt
  // majflt cmajflt utime(14) stime(15) ... vsize(23) rss(24).
  std::string field;
  uint64_t utime = 0, stime = 0;
  int64_t vsize = 0, rss_pages = 0;
  for (int index = 3; index <= 24; ++index) {
    if (!(fields >> field)) return std::nullopt;
    try {
      if (index == 14) utime = std::stoull(field);
      if (index == 15) stime = std::stoull(field);
      if (index == 23) vsize = std::stoll(field);
      if (index == 24) rss_pages = std::stoll(field);
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  ProcessStats p;
  p.cpu_jiffies = utime + stime;
  p.vsize_bytes = vsize;
  p.rss_bytes = rss_pages * static_cast<int64_t>(::sysconf(_SC_PAGESIZE));
  return p;
}

float JiffyFraction(uint64_t used_before, uint64_t used_after,
                    uint64_t total_before, uint64_t total_after) {
  if (total_after <= total_before || used_after < used_before) return 0.0f;
  const double used = static_cast<double>(used_after - used_before);
  const double total = static_cast<double>(total_after - total_before);
  return used >= total ? 1.0f : static_cast<float>(used / total);
}

}  // namespace vimot::deputy

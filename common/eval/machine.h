#pragma once
// The machine a figure was measured on, for tables and JSON summaries.

#include <string>

namespace vimot {
namespace eval {

struct MachineInfo {
  int nproc{0};           // std::thread::hardware_concurrency()
  std::string cpu_model;  // "model name" of /proc/cpuinfo, "unknown" if absent
};

MachineInfo machine_info();

}  // namespace eval
}  // namespace vimot

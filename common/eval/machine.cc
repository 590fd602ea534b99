#include "common/eval/machine.h"

#include <fstream>
#include <thread>

namespace vimot {
namespace eval {

MachineInfo machine_info() {
  MachineInfo m;
  m.nproc = static_cast<int>(std::thread::hardware_concurrency());
  m.cpu_model = "unknown";
  std::ifstream f("/proc/cpuinfo");
  for (std::string line; std::getline(f, line);) {
    if (line.rfind("model name", 0) != 0) continue;
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string v = line.substr(colon + 1);
    const auto b = v.find_first_not_of(" \t");
    m.cpu_model = b == std::string::npos ? "unknown" : v.substr(b);
    break;
  }
  return m;
}

}  // namespace eval
}  // namespace vimot

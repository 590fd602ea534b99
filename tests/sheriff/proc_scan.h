#pragma once
// What is really running, read from /proc: the sheriff tests check live
// processes, not the runner's own bookkeeping. Zombies do not count (they
// run nothing; only their parent can reap them).

#include <sys/types.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace vimot::sheriff::test {

struct ProcInfo {
  pid_t pid{0};
  char state{'?'};
  pid_t pgrp{0};
  std::vector<std::string> argv;
};

/// Every live (non-zombie) process.
inline std::vector<ProcInfo> LiveProcesses() {
  std::vector<ProcInfo> out;
  for (const auto& e : std::filesystem::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream stat_file(e.path() / "stat");
    std::string stat((std::istreambuf_iterator<char>(stat_file)), std::istreambuf_iterator<char>());
    const std::size_t paren = stat.rfind(')');
    if (paren == std::string::npos) continue;  // ended while we looked
    ProcInfo p;
    p.pid = static_cast<pid_t>(std::stol(name));
    std::istringstream rest(stat.substr(paren + 1));
    pid_t ppid = 0;
    rest >> p.state >> ppid >> p.pgrp;
    if (p.state == 'Z' || p.state == 'X') continue;
    std::ifstream cmdline(e.path() / "cmdline");
    for (std::string arg; std::getline(cmdline, arg, '\0');) p.argv.push_back(arg);
    out.push_back(p);
  }
  return out;
}

/// Live members of process group `pgid`.
inline int LiveGroupMembers(pid_t pgid) {
  int n = 0;
  for (const ProcInfo& p : LiveProcesses()) n += p.pgrp == pgid ? 1 : 0;
  return n;
}

/// Live processes whose command line is exactly `argv` (e.g. {"sleep",
/// "30.125"}: test commands use odd durations so no other job matches).
inline int CountRunning(const std::vector<std::string>& argv) {
  int n = 0;
  for (const ProcInfo& p : LiveProcesses()) n += p.argv == argv ? 1 : 0;
  return n;
}

/// argv[0] of a live process, empty if there is none.
inline std::string Program(pid_t pid) {
  for (const ProcInfo& p : LiveProcesses()) {
    if (p.pid == pid && !p.argv.empty()) return p.argv[0];
  }
  return "";
}

}  // namespace vimot::sheriff::test

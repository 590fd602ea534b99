#pragma once
// What happened to a process node's input, for the process's heartbeat
// counters and log (common/process/node_runner.h). Nodes hold the process
// logic without LCM, so this header has none either.

#include <string>

namespace vimot {

struct NodeEvent {
  enum class Kind { kInfo, kDropped, kError } kind{Kind::kInfo};
  std::string message;
};

}  // namespace vimot

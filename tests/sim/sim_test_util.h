#pragma once
// Helpers shared by the simulator tests: the repository's config files.

#include <string>

#include "common/config/config.h"
#include "common/sim/sim_config.h"

namespace vimot {
namespace sim {
namespace test {

/// Absolute path of a file in the source tree (VIMOT_SOURCE_DIR is set by
/// tests/sim/CMakeLists.txt).
inline std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

inline SimConfig load_config(const std::string& relative) {
  return from_config(Config::load_file(source_path(relative)));
}

/// config/sim_paper.yaml as shipped (EuRoC stereo calibration, noise on).
inline SimConfig paper_config() { return load_config("config/sim_paper.yaml"); }

}  // namespace test
}  // namespace sim
}  // namespace vimot

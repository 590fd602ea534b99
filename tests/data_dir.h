#pragma once
// The shared data (../shared/data) for tests tagged [data]: found through env
// VIMOT_DATA_DIR. Without it such a test prints "VIMOT_SKIP" and returns, and
// ctest reports it as skipped (cmake/VimotTest.cmake, DATA), not as passed.

#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <string>

namespace vimot {

/// VIMOT_DATA_DIR/`relative` when that file exists, else "" after a
/// "VIMOT_SKIP" warning naming `what` and the reason.
inline std::string test_data_file_or_skip(const std::string& relative, const std::string& what) {
  const char* root = std::getenv("VIMOT_DATA_DIR");
  if (root == nullptr || *root == '\0') {
    WARN("VIMOT_SKIP: VIMOT_DATA_DIR not set: " << what);
    return "";
  }
  const std::string path = std::string(root) + "/" + relative;
  if (!std::ifstream(path).good()) {
    WARN("VIMOT_SKIP: VIMOT_DATA_DIR=" << root << " has no " << relative << ": " << what);
    return "";
  }
  return path;
}

}  // namespace vimot

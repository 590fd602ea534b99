#pragma once
// main() of the test programs that need the real EuRoC slice: runs Catch2
// with slice_dir() set to $VIMOT_DATA_DIR/euroc_v101_micro, or exits with
// ctest's skip code 77 (SKIP_RETURN_CODE in CMakeLists.txt), saying why,
// when VIMOT_DATA_DIR is unset or has no slice.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

inline std::string& slice_dir() {
  static std::string dir;
  return dir;
}

int main(int argc, char** argv) {
  const char* root = std::getenv("VIMOT_DATA_DIR");
  if (root == nullptr) {
    std::cout << "VIMOT_DATA_DIR not set: skipping\n";
    return 77;
  }
  slice_dir() = std::string(root) + "/euroc_v101_micro";
  if (!std::ifstream(slice_dir() + "/mav0/cam0/data.csv").good()) {
    std::cout << "VIMOT_DATA_DIR=" << root << " has no euroc_v101_micro/mav0/cam0/data.csv: skipping\n";
    return 77;
  }
  return Catch::Session().run(argc, argv);
}

#pragma once
// The stereo image list of an ASL/EuRoC folder (mav0/cam0, mav0/cam1:
// data.csv rows "timestamp [ns],filename"), paired by equal timestamp, for
// the tracker's benchmark and tests. No LCM here.

#include <cstdint>
#include <string>
#include <vector>

namespace vimot::frontend {

struct AslStereoPair {
  int64_t timestamp_ns{0};
  std::string left_path;
  std::string right_path;  // empty when cam1 has no image at this time
};

/// Rows of cam0/data.csv in time order with the cam1 file of the same
/// timestamp; rows whose image file does not exist are skipped (EuRoC
/// excerpts list images they do not ship). Throws std::runtime_error naming
/// the file and line for a missing data.csv or a malformed row.
std::vector<AslStereoPair> read_asl_stereo_pairs(const std::string& mav0_dir);

}  // namespace vimot::frontend

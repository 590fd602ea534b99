#pragma once
// Reader for pose trajectory text files in the TUM format, as OpenVINS's
// simulator reads them (ov_data/sim/*.txt):
//
//   # comment
//   t x y z qx qy qz qw
//
// t in seconds, p_IinG = (x, y, z) in metres, (qx, qy, qz, qw) the
// body-to-world Hamilton quaternion, i.e. the JPL q_GtoI (see
// common/math/quat.h). '#' starts a comment anywhere on a line; blank lines
// are skipped.

#include <string>
#include <vector>

#include "common/sim/bspline_se3.h"

namespace vimot {
namespace sim {

struct PoseTrajectory {
  std::string path;                // the file read
  double t_first{0.0};             // absolute time of the first pose (s)
  std::vector<TimedPose> poses;    // times relative to t_first (first is 0)
};

/// Reads and validates a TUM trajectory file. Throws std::runtime_error
/// naming the file (and line number, 1-based) for: a missing or unreadable
/// file, a line without exactly 8 numbers, a non-finite number, a zero or
/// far-from-unit quaternion (| |q| - 1 | > 1e-3), a time that does not
/// increase strictly, or fewer than 2 poses.
PoseTrajectory load_tum_trajectory(const std::string& path);

/// Same from text already in memory; `source` names it in errors.
PoseTrajectory parse_tum_trajectory(const std::string& text, const std::string& source);

}  // namespace sim
}  // namespace vimot

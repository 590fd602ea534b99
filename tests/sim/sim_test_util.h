#pragma once
// Helpers shared by the simulator tests: the repository's config files,
// the camera pose of a run.

#include <string>

#include "common/config/config.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"

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

/// cam0 pose in G at sim time t, from the IMU pose and the calibration.
inline void cam0_in_G(const Simulator& sim, double t, Eigen::Matrix3d* R_CtoG, Eigen::Vector3d* p_CinG) {
  const SplineState I = sim.robot_state(t);
  const CameraCalibration& calib = sim.cameras().at(0);
  *R_CtoG = I.R_BtoG * calib.R_ItoC.transpose();
  *p_CinG = I.p_BinG - *R_CtoG * calib.p_IinC;
}

}  // namespace test
}  // namespace sim
}  // namespace vimot

#pragma once
// Checkpoint of an estimator's robot state, so a process that was killed
// and respawned goes on from its own estimate instead of starting anew
// (docs/sheriff.md, "Recovery"). It holds the IMU state at the last update,
// its SLAM landmarks (global_xyz only) with their joint covariance, and the
// last IMU reading at or before the state time, from which the gap to the
// new input is interpolated (ImuGapNoise); the first frames after the gap
// re-lock on the landmarks. Clones, MSCKF tracks and the target are not
// kept: dropping them from the state is marginalising them, which keeps
// the covariance consistent. No LCM here.
//
// File: "VIMOTCK2", the payload (utimes, landmark count and ids, values,
// joint covariance [IMU 15, 3 per landmark]; native byte order: the same
// machine reads it) and its 64-bit FNV-1a hash; written to PATH.tmp and
// renamed, so a reader sees a whole checkpoint or the previous one.

#include <string>
#include <vector>

#include "common/estimator/vio_estimator.h"
#include "common/types/nav_state.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace estimator {

struct CheckpointLandmark {
  int64_t feature_id{0};
  Eigen::Vector3d p_FinG{Eigen::Vector3d::Zero()};
  Eigen::Vector3d p_FinG_fej{Eigen::Vector3d::Zero()};  // its first estimate
};

struct RobotCheckpoint {
  NavState state;    // utime, q_GtoI, p, v, biases, IMU covariance (counts not kept)
  ImuData last_imu;  // utime <= state.utime
  std::vector<CheckpointLandmark> landmarks;
  /// Joint covariance [IMU; landmarks in order], 15 + 3n square (its IMU
  /// block is state.covariance).
  Eigen::MatrixXd covariance;
};

/// The initialised estimator's checkpoint: its state at the last update and
/// the newest buffered IMU reading at or before it.
RobotCheckpoint checkpoint_of(const VioEstimator& estimator);

/// Initialises the estimator from a checkpoint (its state time is the
/// checkpoint's; the reading goes before the buffered IMU samples).
void restore(const RobotCheckpoint& checkpoint, VioEstimator* estimator);

/// Writes atomically; false (with *why) if the file cannot be written.
bool write_checkpoint(const std::string& path, const RobotCheckpoint& checkpoint, std::string* why);

/// Reads and validates (size, magic, hash, finite values, unit quaternion,
/// symmetric covariance with a positive diagonal, reading not after the
/// state); false with *why (naming the file) if absent or unusable.
bool read_checkpoint(const std::string& path, RobotCheckpoint* checkpoint, std::string* why);

}  // namespace estimator
}  // namespace vimot

#pragma once
// The published form of a target estimate (TARGET_STATE / OBJECT_STATE,
// TARGET_PREDICTION / OBJECT_PREDICTION; common/types/target_state.h):
// both poses (the estimated one and the other from the IMU pose at the same
// time), velocities, covariance; a global prediction with the target
// relative to the robot pose at utime (the robot is not predicted). Shared
// by the stereo target filter and the monocular object filter.

#include <cstdint>

#include "common/target/target_model.h"
#include "common/target/target_types.h"
#include "common/types/target_state.h"

namespace vimot {
namespace target {

/// x (in `representation`) with covariance P at utime; imu_pose = [q_GtoI, p_IinG] at utime.
TargetStateEstimate target_state_estimate(int64_t utime, TargetRepresentation representation, const TargetValue& x,
                                          const Matrix12d& P, const PoseValue& imu_pose, int num_target_points,
                                          int start_count);

/// A global prediction made at utime for utime + horizon_s.
TargetPosePrediction target_pose_prediction(int64_t utime, double horizon_s, const TargetPrediction& prediction,
                                            const PoseValue& imu_pose);

}  // namespace target
}  // namespace vimot

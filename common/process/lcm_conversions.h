#pragma once
// The one place where LCM messages become plain vimot types and back, so the
// algorithms never see an LCM type. from_lcm() checks what a message could
// get wrong (non-finite numbers, bad counts, camera ids) and throws
// std::invalid_argument saying what; the scaffold counts it as an error.

#include <optional>

#include "common/frontend/box.h"
#include "common/object/scale_estimator.h"
#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"
#include "common/types/object_pose.h"
#include "common/types/sensor_data.h"
#include "common/types/target_box.h"
#include "common/types/target_state.h"
#include "vimot/features_t.hpp"
#include "vimot/ground_truth_t.hpp"
#include "vimot/imu_t.hpp"
#include "vimot/metric_object_pose_t.hpp"
#include "vimot/nav_state_t.hpp"
#include "vimot/object_pose_t.hpp"
#include "vimot/scale_estimate_t.hpp"
#include "vimot/target_box_t.hpp"
#include "vimot/target_prediction_t.hpp"
#include "vimot/target_state_t.hpp"

namespace vimot {

imu_t to_lcm(const ImuData& imu);
ImuData from_lcm(const imu_t& msg);

features_t to_lcm(const CameraFrame& frame);
CameraFrame from_lcm(const features_t& msg);

ground_truth_t to_lcm(const GroundTruth& truth);
GroundTruth from_lcm(const ground_truth_t& msg);

nav_state_t to_lcm(const NavState& state);
NavState from_lcm(const nav_state_t& msg);

target_state_t to_lcm(const TargetStateEstimate& state);
TargetStateEstimate from_lcm(const target_state_t& msg);

/// The covariance and velocity are not read (offline tools need the boxes).
CameraTargetBox from_lcm(const target_box_t& msg);

target_prediction_t to_lcm(const TargetPosePrediction& prediction);
TargetPosePrediction from_lcm(const target_prediction_t& msg);

/// A target box message's box: the filtered box when the box filter holds
/// one, else this frame's raw detection, else none. Values are not checked
/// (the feature tracker counts a non-finite box as an error).
std::optional<frontend::Box> box_of(const target_box_t& msg);

// Object tracker (issue 5).
object_pose_t to_lcm(const ObjectPoseEstimate& estimate);
ObjectPoseEstimate from_lcm(const object_pose_t& msg);

// --- scale estimator (issue 5): OBJECT_POSE_UPTOSCALE in, SCALE_ESTIMATE and
// OBJECT_POSE_METRIC out.


scale_estimate_t to_lcm(const scale::ScaleResult& result);
metric_object_pose_t to_lcm(const scale::ObjectPoseInWorld& pose);
scale::ScaleResult from_lcm(const scale_estimate_t& msg);
/// p_OinC is not in the message (left zero).
scale::ObjectPoseInWorld from_lcm(const metric_object_pose_t& msg);

}  // namespace vimot

#pragma once
// Output types of the simulator: the events it emits in time order and the
// truth an evaluator needs. No LCM here: drivers/sim converts them.

#include <Eigen/Core>
#include <cstdint>
#include <variant>
#include <vector>

#include "common/types/ground_truth.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace sim {

// The measurements and the truth are vimot's shared plain types
// (common/types), so the LCM adapters and the estimators take them as they
// come. The sim:: names are aliases of those types.
//  * ImuData: w_IinI (rad/s, body rate in I) and a_IinI (m/s², specific
//    force in I) as the sensor outputs them.
//  * CameraFrame: all observations of all cameras at one utime, sorted by
//    camera_id, then feature_id. FeatureObservation::feature_id is the track
//    id (persistent while tracked, fresh after a loss, shared by a stereo
//    pair); the 3D point behind it is Simulator::landmark_of_feature().
//  * GroundTruth: robot state, true biases and (has_target) the target state.
using ImuSample = vimot::ImuData;
using FeatureObservation = vimot::FeatureObservation;
using CameraFrame = vimot::CameraFrame;
using GroundTruth = vimot::GroundTruth;

/// Events in time order; at equal utime: ImuSample, GroundTruth, CameraFrame.
using SimEvent = std::variant<vimot::ImuData, vimot::GroundTruth, vimot::CameraFrame>;

/// A simulated 3D point. Static points are fixed in G; target points are
/// fixed in T (p is p_FinT) on a face with outward normal normal_T.
struct Landmark {
  int64_t id{-1};        // = index in Simulator::landmarks()
  bool is_target{false};
  Eigen::Vector3d p{Eigen::Vector3d::Zero()};         // m: p_FinG (static) or p_FinT (target)
  Eigen::Vector3d normal_T{Eigen::Vector3d::Zero()};  // target points: outward face normal in T
};

}  // namespace sim
}  // namespace vimot

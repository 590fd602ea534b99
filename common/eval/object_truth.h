#pragma once
// Truth of the up-to-scale object pose from the simulator, for the tracker
// tests and the evaluator. The tracker's object frame O (see
// common/object/object_tracker.h) is rigid in the target T:
//  * R_OtoC0 = I at the reference frame, so R_OtoT = R_TtoC0^T;
//  * O sits at s_true along the centre ray u: p_OinC0 = s_true u, where
//    s_true = median of the true distances |p_FinC0| of the reference
//    features (the same definition the tracker applied to its estimate);
// then at any time R_OtoC = R_TtoC R_OtoT and p_OinC = R_TtoC p_OinT + p_TinC,
// to be compared with quat_to_rot(q_OtoC) and s_true * pbar_OinC.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>
#include <vector>

#include "common/object/object_tracker.h"
#include "common/sim/renderer.h"
#include "common/sim/simulator.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace eval {

/// True pose of the target T in cam0 at a utime.
struct TargetInCamera {
  Eigen::Matrix3d R_TtoC{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_TinC{Eigen::Vector3d::Zero()};
};

/// True pose of the world G in cam0 at a utime (R_GtoC, p_GinC as R_TtoC, p_TinC).
inline TargetInCamera true_world_in_camera(const sim::Simulator& sim, int64_t utime) {
  const sim::SplineState robot = sim.robot_state(sim.sim_time(utime));
  const CameraCalibration& cam = sim.cameras().at(0);
  // p_C = R_ItoC p_I + p_IinC and p_I = R_GtoI (p_G - p_IinG).
  const Eigen::Matrix3d R_GtoC = cam.R_ItoC * robot.R_BtoG.transpose();
  return {R_GtoC, cam.p_IinC - R_GtoC * robot.p_BinG};
}

inline TargetInCamera true_target_in_camera(const sim::Simulator& sim, int64_t utime) {
  const sim::SplineState target = sim.target_state(sim.sim_time(utime)).value();
  const TargetInCamera g = true_world_in_camera(sim, utime);
  return {g.R_TtoC * target.R_BtoG, g.R_TtoC * target.p_BinG + g.p_TinC};
}

/// The true object frame of one track: O in T and the true scale.
struct ObjectTruth {
  double s_true{0.0};  // m per tracker unit
  Eigen::Matrix3d R_OtoT{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_OinT{Eigen::Vector3d::Zero()};

  Eigen::Matrix3d R_OtoC(const TargetInCamera& x) const { return x.R_TtoC * R_OtoT; }
  Eigen::Vector3d p_OinC(const TargetInCamera& x) const { return x.R_TtoC * p_OinT + x.p_TinC; }
};

/// The true object frame of a track whose reference features lie at the
/// true distances `distances` (m) from cam0 at facts.reference_utime.
inline ObjectTruth object_truth_at_distances(const sim::Simulator& sim, const InitFacts& facts,
                                             std::vector<double> distances) {
  if (distances.empty()) throw std::runtime_error("object truth: no reference feature");
  const TargetInCamera x0 = true_target_in_camera(sim, facts.reference_utime);
  // Same median as the tracker: the upper middle element.
  const auto mid = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), mid, distances.end());
  ObjectTruth truth;
  truth.s_true = *mid;
  truth.R_OtoT = x0.R_TtoC.transpose();
  truth.p_OinT = x0.R_TtoC.transpose() * (truth.s_true * facts.centre_ray_C0 - x0.p_TinC);
  return truth;
}

/// The true object frame of a track on the simulator's own feature tracks
/// (feature ids name the simulator's landmarks).
inline ObjectTruth object_truth(const sim::Simulator& sim, const InitFacts& facts) {
  const TargetInCamera x0 = true_target_in_camera(sim, facts.reference_utime);
  std::vector<double> distances;
  for (int64_t feature_id : facts.reference_feature_ids) {
    const int64_t landmark = sim.landmark_of_feature(feature_id);
    if (landmark < 0 || !sim.landmarks().at(static_cast<std::size_t>(landmark)).is_target) {
      throw std::runtime_error("reference feature is not a target landmark");
    }
    const Eigen::Vector3d& p_FinT = sim.landmarks()[static_cast<std::size_t>(landmark)].p;
    distances.push_back((x0.R_TtoC * p_FinT + x0.p_TinC).norm());
  }
  return object_truth_at_distances(sim, facts, std::move(distances));
}

/// The same from pixels, where feature ids are the feature tracker's, not
/// the simulator's landmarks: a reference feature's true distance is that of
/// the surface its cam0 pixel in `reference` (the frame at
/// facts.reference_utime) shows, by the renderer's ray cast.
inline ObjectTruth object_truth_from_pixels(const sim::Simulator& sim, const sim::Renderer& renderer,
                                            const InitFacts& facts, const CameraFrame& reference) {
  if (reference.utime != facts.reference_utime) throw std::invalid_argument("object truth: not the reference frame");
  const TargetInCamera g = true_world_in_camera(sim, facts.reference_utime);
  std::vector<double> distances;
  for (int64_t id : facts.reference_feature_ids) {
    for (const FeatureObservation& f : reference.observations) {
      if (f.camera_id != 0 || f.feature_id != id) continue;
      const sim::Renderer::SurfaceHit hit = renderer.surface_at(0, facts.reference_utime, f.pixel);
      distances.push_back((g.R_TtoC * hit.p_inG + g.p_TinC).norm());
    }
  }
  return object_truth_at_distances(sim, facts, std::move(distances));
}

}  // namespace eval
}  // namespace vimot

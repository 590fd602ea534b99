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
#include <vector>

#include "common/object/object_tracker.h"
#include "common/sim/simulator.h"

namespace vimot {
namespace eval {

/// True pose of the target T in cam0 at a utime.
struct TargetInCamera {
  Eigen::Matrix3d R_TtoC{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_TinC{Eigen::Vector3d::Zero()};
};

inline TargetInCamera true_target_in_camera(const sim::Simulator& sim, int64_t utime) {
  const double t = sim.sim_time(utime);
  const sim::SplineState robot = sim.robot_state(t);
  const sim::SplineState target = sim.target_state(t).value();
  const CameraCalibration& cam = sim.cameras().at(0);
  // p_C = R_ItoC p_I + p_IinC and p_I = R_GtoI (p_G - p_IinG).
  const Eigen::Matrix3d R_GtoC = cam.R_ItoC * robot.R_BtoG.transpose();
  const Eigen::Vector3d p_GinC = cam.p_IinC - R_GtoC * robot.p_BinG;
  return {R_GtoC * target.R_BtoG, R_GtoC * target.p_BinG + p_GinC};
}

/// The true object frame of one track: O in T and the true scale.
struct ObjectTruth {
  double s_true{0.0};  // m per tracker unit
  Eigen::Matrix3d R_OtoT{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_OinT{Eigen::Vector3d::Zero()};

  Eigen::Matrix3d R_OtoC(const TargetInCamera& x) const { return x.R_TtoC * R_OtoT; }
  Eigen::Vector3d p_OinC(const TargetInCamera& x) const { return x.R_TtoC * p_OinT + x.p_TinC; }
};

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
  // Same median as the tracker: the upper middle element.
  const auto mid = distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2);
  std::nth_element(distances.begin(), mid, distances.end());
  ObjectTruth truth;
  truth.s_true = *mid;
  truth.R_OtoT = x0.R_TtoC.transpose();
  truth.p_OinT = x0.R_TtoC.transpose() * (truth.s_true * facts.centre_ray_C0 - x0.p_TinC);
  return truth;
}

}  // namespace eval
}  // namespace vimot

#pragma once
// Motion generation of the three scenarios: each yields B-splines for the
// IMU pose T_ItoG and (when present) the target pose T_TtoG, so the true
// angular velocity and acceleration are exact spline derivatives.
//
//  * paper: the target (box centre T) drives a counter-clockwise semicircle
//    of radius r at constant speed on the plane z = base_height + size_z/2,
//    heading along the path (planar: yaw-only rotation, velocity in its x-y
//    plane); with paper.target_motion rc_car it drives RcCarCourse instead
//    (same start, length and plane; speed and curvature varying, stops),
//    drawn from map_seed. The UAV camera stays `standoff` behind it along the path
//    tangent, `lateral_offset` to the left, at `height` above the floor, plus
//    the oscillation; its optical axis points at the target centre with the
//    camera x axis horizontal, and R_ItoG = R_CtoG R_ItoC (cam0).
//  * trajectory: a TUM file fitted as OpenVINS does (BsplineSE3::fit).
//  * mono: an object moving on a Lissajous path on the floor, heading along
//    its velocity; a hand-held camera defined by MonoScenarioConfig (anchor,
//    pointing, sums of sinusoids), body pose from cam0's extrinsics.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <optional>

#include "common/camera/camera_model.h"
#include "common/sim/bspline_se3.h"
#include "common/sim/sim_config.h"

namespace vimot {
namespace sim {

struct ScenarioMotion {
  BsplineSE3 robot;                  // T_ItoG over spline time
  std::optional<BsplineSE3> target;  // T_TtoG over spline time
  double t_begin{0.0};               // spline time of simulation time 0
  double duration{0.0};              // s
  Eigen::AlignedBox2d workspace;     // floor rectangle of the static map (may be empty)
};

/// Builds the motion of config.scenario (cameras must hold cam0 for the
/// paper and mono scenarios). Throws std::invalid_argument / runtime_error.
ScenarioMotion make_scenario(const SimConfig& config);

/// Camera-to-world rotation whose optical axis (z) points from p_CinG at
/// p_lookG with the camera x axis horizontal (⊥ world z) and y pointing
/// down. Throws std::invalid_argument when looking (almost) straight up or
/// down, where "horizontal x" is undefined.
Eigen::Matrix3d look_at_R_CtoG(const Eigen::Vector3d& p_CinG, const Eigen::Vector3d& p_lookG);

/// T_ItoG of the body carrying `cam` when that camera has pose (R_CtoG, p_CinG).
Eigen::Matrix4d body_pose_from_camera(const Eigen::Matrix3d& R_CtoG, const Eigen::Vector3d& p_CinG,
                                      const CameraCalibration& cam);

/// Sum of sinusoids at time t (s).
Eigen::Vector3d eval_sinusoids(const std::vector<Sinusoid3>& terms, double t);

}  // namespace sim
}  // namespace vimot

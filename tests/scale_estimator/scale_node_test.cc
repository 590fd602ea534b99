// The scale_estimator process logic without LCM (ScaleNode): IMU -> camera
// pose, pairing by utime, stale / out-of-order input, tracking loss, the
// held scale of the metric pose. Motions: the synthetic normal case of
// scale_scenarios.h (accepted with the default options, s = 2.5).
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include "common/config/config.h"
#include "common/math/quat.h"
#include "procs/scale_estimator/scale_node.h"
#include "scale_scenarios.h"

using namespace vimot;
using namespace vimot::scale;
using namespace vimot::scale::testing;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kScale = 2.5;

// A EuRoC-like cam0: optical axis along the IMU's x, 6 cm lateral offset.
CameraCalibration test_camera() {
  CameraCalibration c;
  c.R_ItoC = exp_so3(Eigen::Vector3d(0.01, -0.02, 0.03)) * (Eigen::Matrix3d() << 0, -1, 0, 0, 0, -1, 1, 0, 0).finished();
  c.p_IinC = Eigen::Vector3d(0.065, -0.02, -0.01);
  return c;
}

// The IMU state whose camera has the observation's pose: I's origin is
// p_IinC in C, so p_IinG = p_CinG + R_CtoG p_IinC, and R_ItoG = R_CtoG R_ItoC.
NavState state_of(const ScaleObservation& o, const CameraCalibration& cam) {
  NavState s;
  s.utime = o.utime;
  s.updated = true;
  const Eigen::Matrix3d R_CtoG = o.R_CtoG();
  s.q_GtoI = rot_to_quat((R_CtoG * cam.R_ItoC).transpose());
  s.p_IinG = o.p_CinG + R_CtoG * cam.p_IinC;
  return s;
}

ObjectPoseEstimate pose_of(const ScaleObservation& o) {
  ObjectPoseEstimate p;
  p.utime = o.utime;
  p.valid = true;
  p.q_OtoC = o.q_OtoC;
  p.pbar_OinC = o.pbar_OinC;
  return p;
}

struct Outputs {
  std::vector<ScaleResult> scales;
  std::vector<ObjectPoseInWorld> poses;
  std::vector<NodeEvent> events;
};

ScaleNode make_node(Outputs* out, int max_pending = 10) {
  ScaleNodeOptions o;
  o.camera = test_camera();
  o.max_pending = max_pending;
  return ScaleNode(
      o, [out](const ScaleResult& r) { out->scales.push_back(r); },
      [out](const ObjectPoseInWorld& p) { out->poses.push_back(p); },
      [out](const NodeEvent& e) { out->events.push_back(e); });
}

}  // namespace

TEST_CASE("scale_node: camera pose from the IMU pose, hand-derived case", "[scale]") {
  // R_ItoC = Rz(90°), p_IinC = (1, 0, 0): C's origin is at p_CinI = -R_ItoC^T p_IinC
  // = (0, 1, 0) (check: R_ItoC (0, 1, 0) + p_IinC = (-1, 0, 0) + (1, 0, 0) = 0).
  // R_GtoI = Rx(90°), p_IinG = (0, 0, 1): R_ItoG (0, 1, 0) = Rx(-90°) (0, 1, 0) = (0, 0, -1),
  // so p_CinG = (0, 0, 0). C's z axis is I's z (Rz keeps it), in G Rx(-90°) e_z = (0, 1, 0);
  // C's x axis is I's -y, in G Rx(-90°) (0, -1, 0) = (0, 0, 1).
  CameraCalibration cam;
  cam.R_ItoC = exp_so3(Eigen::Vector3d(0, 0, M_PI / 2));
  cam.p_IinC = Eigen::Vector3d(1, 0, 0);
  const Eigen::Vector4d q_GtoI = rot_to_quat(exp_so3(Eigen::Vector3d(M_PI / 2, 0, 0)));
  const CameraPoseInWorld c = camera_pose_in_world(q_GtoI, Eigen::Vector3d(0, 0, 1), cam);
  CHECK(c.p_CinG.norm() < 1e-12);
  CHECK((c.R_CtoG * Eigen::Vector3d::UnitZ() - Eigen::Vector3d(0, 1, 0)).norm() < 1e-12);
  CHECK((c.R_CtoG * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, 0, 1)).norm() < 1e-12);
}

TEST_CASE("scale_node: pairs by utime in either arrival order, ignores IMU-rate states", "[scale]") {
  Outputs out;
  ScaleNode node = make_node(&out);
  const CameraCalibration cam = test_camera();
  const std::vector<ScaleObservation> obs = generate(normal_camera, normal_object, kScale, 260);
  for (std::size_t k = 0; k < obs.size(); ++k) {
    NavState propagated = state_of(obs[k], cam);
    propagated.updated = false;
    propagated.p_IinG.x() += 100.0;  // would spoil the estimate if used
    node.on_nav_state(propagated);
    // Alternate which side arrives first.
    if (k % 2 == 0) {
      node.on_nav_state(state_of(obs[k], cam));
      node.on_object_pose(pose_of(obs[k]));
    } else {
      node.on_object_pose(pose_of(obs[k]));
      node.on_nav_state(state_of(obs[k], cam));
    }
  }
  const ScaleNodeStats& s = node.stats();
  CHECK(s.pairs == 260);
  CHECK(s.states_in == 260);
  CHECK(s.stale_states + s.stale_object_poses + s.duplicate_or_backwards + s.rejected_observations == 0);
  CHECK(node.pending_states() + node.pending_object_poses() == 0);
  // Camera poses rebuilt from the IMU states equal the originals.
  const ScaleObservation& last = node.estimator().window().back();
  CHECK((last.p_CinG - obs.back().p_CinG).norm() < 1e-9);
  CHECK(rotation_angle_between(last.R_CtoG(), obs.back().R_CtoG()) < 1e-9);
  // An estimate per pair once the window (200) is full, all accepted at s.
  REQUIRE(out.scales.size() == 61);
  for (const ScaleResult& r : out.scales) {
    CHECK(r.accepted);
    CHECK_THAT(r.scale, WithinRel(kScale, 1e-6));
  }
  CHECK(out.poses.size() == 61);
  CHECK(out.poses.back().utime == obs.back().utime);
}

TEST_CASE("scale_node: a side that lags is buffered; passed or overflowing messages are stale", "[scale]") {
  Outputs out;
  ScaleNode node = make_node(&out, /*max_pending=*/3);
  const CameraCalibration cam = test_camera();
  const std::vector<ScaleObservation> obs = generate(normal_camera, normal_object, kScale, 13);
  // VINS lags by 3 frames: the object poses wait, then all pair.
  for (int k = 0; k < 3; ++k) node.on_object_pose(pose_of(obs[k]));
  CHECK(node.pending_object_poses() == 3);
  for (int k = 0; k < 3; ++k) node.on_nav_state(state_of(obs[k], cam));
  CHECK(node.stats().pairs == 3);
  CHECK(node.pending_object_poses() == 0);
  // Frame 3 has no object pose (tracker skipped it): its state is stale once frame 4's pose arrives.
  node.on_nav_state(state_of(obs[3], cam));
  node.on_object_pose(pose_of(obs[4]));
  CHECK(node.stats().stale_states == 1);
  CHECK(node.pending_states() == 0);
  CHECK(node.pending_object_poses() == 1);
  node.on_nav_state(state_of(obs[4], cam));
  CHECK(node.stats().pairs == 4);
  // Frame 5's object pose comes after VINS passed it (VINS skipped frame 5): stale at once.
  node.on_nav_state(state_of(obs[6], cam));
  node.on_object_pose(pose_of(obs[5]));
  CHECK(node.stats().stale_object_poses == 1);
  CHECK(node.pending_object_poses() == 0);
  CHECK(node.pending_states() == 1);
  node.on_object_pose(pose_of(obs[6]));
  CHECK(node.stats().pairs == 5);
  // VINS silent: beyond max_pending the oldest object poses are dropped.
  for (int k = 7; k < 12; ++k) node.on_object_pose(pose_of(obs[k]));
  CHECK(node.pending_object_poses() == 3);
  CHECK(node.stats().stale_object_poses == 1 + 2);
  for (int k = 9; k < 12; ++k) node.on_nav_state(state_of(obs[k], cam));
  CHECK(node.stats().pairs == 8);
  // Duplicates and time going backwards, per channel.
  node.on_nav_state(state_of(obs[11], cam));
  node.on_object_pose(pose_of(obs[10]));
  CHECK(node.stats().duplicate_or_backwards == 2);
  CHECK(node.stats().pairs == 8);
  // A NaN in a pair is refused by the core, counted, and changes nothing.
  ObjectPoseEstimate bad = pose_of(obs[12]);
  bad.pbar_OinC.y() = std::numeric_limits<double>::quiet_NaN();
  node.on_object_pose(bad);
  node.on_nav_state(state_of(obs[12], cam));
  CHECK(node.stats().rejected_observations == 1);
  CHECK(node.estimator().window().size() == 8);
  int dropped = 0;
  for (const NodeEvent& e : out.events) dropped += e.kind == NodeEvent::Kind::kDropped;
  CHECK(dropped == 1 + 3 + 2 + 1);
}

TEST_CASE("scale_node: held scale for the metric pose; tracking loss resets", "[scale]") {
  Outputs out;
  ScaleNode node = make_node(&out);
  const CameraCalibration cam = test_camera();
  const std::vector<ScaleObservation> normal = generate(normal_camera, normal_object, kScale, 220);
  for (const ScaleObservation& o : normal) {
    node.on_nav_state(state_of(o, cam));
    node.on_object_pose(pose_of(o));
  }
  REQUIRE(node.estimator().has_scale());
  CHECK_THAT(node.estimator().scale(), WithinRel(kScale, 1e-6));

  // The camera stops at its last pose. Windows that still hold part of the
  // motion may be accepted (at another scale: the truncated motions are no
  // longer uncorrelated); once the window holds only the static part, (ii)
  // fails and the metric poses use the last accepted scale.
  const Pose parked = normal_camera(219 * kDt);
  auto static_camera = [&parked](double) { return parked; };
  const std::vector<ScaleObservation> still = generate(static_camera, normal_object, kScale, 220, 220);
  double held = std::numeric_limits<double>::quiet_NaN();
  for (const ScaleObservation& o : still) {
    node.on_nav_state(state_of(o, cam));
    node.on_object_pose(pose_of(o));
    if (out.scales.back().accepted) held = out.scales.back().scale;
  }
  REQUIRE(std::isfinite(held));
  CHECK(!out.scales.back().accepted);
  CHECK(out.scales.back().failed_condition == 2);
  const ObjectPoseInWorld& metric = out.poses.back();
  CHECK(metric.utime == still.back().utime);
  CHECK(metric.scale == held);
  // Eq. 21 from the truth: p_OinG = p_CinG + held * R_CtoG pbar_OinC, where
  // s * R_CtoG pbar_OinC is the true camera-to-object vector.
  const Eigen::Vector3d p_CinG = parked.p_XinG;
  const Eigen::Vector3d p_true = normal_object((219 + 220) * kDt).p_XinG;
  CHECK((metric.p_OinG - (p_CinG + held / kScale * (p_true - p_CinG))).norm() < 1e-9);

  // Tracking lost for a frame: the window is cleared (no finite difference
  // across the gap), the held scale stays.
  ObjectPoseEstimate lost;
  lost.utime = still.back().utime + 50000;
  lost.valid = false;
  lost.pbar_OinC.x() = std::numeric_limits<double>::quiet_NaN();  // meaningless when invalid
  node.on_object_pose(lost);
  CHECK(node.stats().invalid_object_poses == 1);
  CHECK(node.estimator().window().empty());
  CHECK(node.estimator().has_scale());

  // A new track (re-initialised tracker, new length unit): window and held
  // scale forgotten, no metric pose until a new scale is accepted.
  const std::size_t poses_before = out.poses.size();
  std::vector<ScaleObservation> again = generate(normal_camera, normal_object, kScale, 199, 500);
  for (const ScaleObservation& o : again) {
    node.on_nav_state(state_of(o, cam));
    ObjectPoseEstimate p = pose_of(o);
    p.track_id = 2;
    node.on_object_pose(p);
  }
  CHECK(node.stats().new_tracks == 1);
  CHECK(!node.estimator().has_scale());
  CHECK(out.poses.size() == poses_before);
  CHECK(node.estimator().window().size() == 199);
}

TEST_CASE("scale_node: the object filter's state and prediction per metric pose, reset on a new track", "[scale]") {
  Outputs out;
  std::vector<TargetStateEstimate> states;
  std::vector<TargetPosePrediction> predictions;
  ScaleNodeOptions options;
  options.camera = test_camera();
  options.prediction_horizon_s = 0.25;
  // The synthetic object shakes (up to ~14 m/s², 4 rad/s²), no ground robot: a matching random walk.
  options.filter.noise = target::TargetNoise::isotropic(20.0, 5.0);
  ScaleNode node(
      options, [&out](const ScaleResult& r) { out.scales.push_back(r); },
      [&out](const ObjectPoseInWorld& p) { out.poses.push_back(p); }, {},
      [&](const TargetStateEstimate& s, const TargetPosePrediction& p) {
        states.push_back(s);
        predictions.push_back(p);
      });
  const CameraCalibration cam = test_camera();
  const std::vector<ScaleObservation> normal = generate(normal_camera, normal_object, kScale, 260);
  NavState last_state;
  for (const ScaleObservation& o : normal) {
    last_state = state_of(o, cam);
    node.on_nav_state(last_state);
    node.on_object_pose(pose_of(o));
  }
  REQUIRE(!out.poses.empty());
  // Noise-free poses of a smooth motion: every one passes the gate.
  CHECK(states.size() == out.poses.size());
  CHECK(node.stats().object_states == static_cast<int64_t>(states.size()));
  CHECK(node.filter().stats().initializations == 1);
  CHECK(node.filter().stats().outliers == 0);

  const TargetStateEstimate& s = states.back();
  const ObjectPoseInWorld& metric = out.poses.back();
  CHECK(s.utime == metric.utime);
  CHECK(s.representation == TargetFrame::kGlobal);
  CHECK(s.num_target_points == 0);
  CHECK((s.p_TinG - metric.p_OinG).norm() < 0.01);  // the filter follows the (exact) poses
  CHECK(rotation_angle_between(quat_to_rot(s.q_GtoT), metric.R_OtoG.transpose()) < 0.01);
  // The robot-relative pose is the world pose seen from the paired VINS IMU pose.
  const Eigen::Matrix3d R_GtoI = quat_to_rot(last_state.q_GtoI);
  CHECK((s.p_TinI - R_GtoI * (s.p_TinG - last_state.p_IinG)).norm() < 1e-9);
  CHECK(quat_to_rot(s.q_ItoT).isApprox(quat_to_rot(s.q_GtoT) * R_GtoI.transpose(), 1e-9));
  CHECK(s.covariance.isApprox(node.filter().covariance()));
  const TargetPosePrediction& p = predictions.back();
  CHECK(p.utime == s.utime);
  CHECK(p.prediction_utime == s.utime + 250000);
  const target::TargetPrediction expected = node.filter().predict(0.25);
  CHECK(p.p_TinG.isApprox(expected.x.p_TinR));
  CHECK(p.q_GtoT.isApprox(expected.x.q_RtoT));
  CHECK(p.covariance.trace() > s.covariance.topLeftCorner<6, 6>().trace());

  // A new track: the filter is reset with the scale; nothing published until a new scale.
  const std::size_t states_before = states.size();
  for (const ScaleObservation& o : generate(normal_camera, normal_object, kScale, 100, 500)) {
    node.on_nav_state(state_of(o, cam));
    ObjectPoseEstimate pe = pose_of(o);
    pe.track_id = 2;
    node.on_object_pose(pe);
  }
  CHECK(node.stats().new_tracks == 1);
  CHECK(!node.filter().initialized());
  CHECK(states.size() == states_before);
}

TEST_CASE("scale_node: object_filter options from the config, unknown keys and bad values refused", "[scale]") {
  ScaleNodeOptions o;
  const Config cfg = Config::from_string(
      "object_filter:\n  sigma_v: 0.2\n  sigma_w: 0.7\n  k_depth: 0.01\n  sigma_theta: [0.01, 0.02, 0.03]\n"
      "  max_consecutive_rejections: 3\n  prediction_horizon_s: 1.5\n");
  object_filter_options_from_config(cfg, &o);
  CHECK(o.filter.noise.sigma_v == Eigen::Vector3d::Constant(0.2));
  CHECK(o.filter.noise.sigma_w == Eigen::Vector3d::Constant(0.7));
  CHECK(o.filter.k_depth == 0.01);
  CHECK(o.filter.k_lateral == target::ObjectPoseFilterOptions().k_lateral);
  CHECK(o.filter.sigma_theta_C == Eigen::Vector3d(0.01, 0.02, 0.03));
  CHECK(o.filter.max_consecutive_rejections == 3);
  CHECK(o.prediction_horizon_s == 1.5);
  ScaleNodeOptions d;
  object_filter_options_from_config(Config::from_string("node:\n  max_pending: 3\n"), &d);  // no section: defaults
  CHECK(d.prediction_horizon_s == 0.5);
  CHECK_THROWS_AS(object_filter_options_from_config(Config::from_string("object_filter:\n  sigma_x: 1\n"), &d),
                  ConfigError);
  CHECK_THROWS_AS(object_filter_options_from_config(Config::from_string("object_filter:\n  k_depth: -1\n"), &d),
                  ConfigError);
  CHECK_THROWS_AS(
      object_filter_options_from_config(Config::from_string("object_filter:\n  prediction_horizon_s: -1\n"), &d),
      ConfigError);
}

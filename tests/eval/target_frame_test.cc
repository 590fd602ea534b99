// The fixed transform between a filter's target frame and the true one
// (common/eval/target_frame.h) against hand-built rigid-body truth.

#include <catch2/catch.hpp>

#include <cmath>

#include "common/eval/metrics.h"
#include "common/eval/target_frame.h"
#include "common/eval/truth_matcher.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::eval;

namespace {

// A target turning at constant w about its z axis and driving forward at v
// (in T), seen from a fixed IMU.
GroundTruth truth_at(double t) {
  GroundTruth g;
  g.utime = static_cast<int64_t>(1e6 * t);
  g.q_GtoI = quat_normalize(Eigen::Vector4d(0.1, -0.2, 0.3, 0.9));
  g.p_IinG = Eigen::Vector3d(1.0, 2.0, 3.0);
  g.has_target = true;
  const double w = 0.4, v = 1.5, r = v / w;
  const double yaw = 0.3 + w * t;
  g.q_GtoT = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, yaw)).transpose());  // R_GtoT = Rz(yaw)ᵀ
  g.p_TinG = Eigen::Vector3d(5.0 + r * std::sin(yaw), -1.0 - r * std::cos(yaw), 0.5);
  g.v_TinT = Eigen::Vector3d(v, 0.0, 0.0);
  g.w_TinT = Eigen::Vector3d(0.0, 0.0, w);
  return g;
}


// The estimate of a filter whose frame is T ∘ X, exact: the truth seen in that frame.
TargetStateEstimate exact_estimate(double t, const TargetFrameTransform& X, int start_count = 0) {
  const GroundTruth g = in_target_frame(truth_at(t), X);
  const TargetInImu ti = true_target_in_imu(g);
  TargetStateEstimate e;
  e.utime = g.utime;
  e.q_ItoT = ti.q_ItoT;
  e.p_TinI = ti.p_TinI;
  e.q_GtoT = g.q_GtoT;
  e.p_TinG = g.p_TinG;
  e.covariance = Eigen::Matrix<double, 12, 12>::Identity() * 1e-4;
  e.start_count = start_count;
  return e;
}
}  // namespace

TEST_CASE("target frame transform: the filter's frame at the start, the same body frame later", "[eval][target]") {
  const GroundTruth t0 = truth_at(0.0);
  // The filter's frame: rotated and shifted from the true one.
  const Eigen::Matrix3d R_TtoT2 = exp_so3(Eigen::Vector3d(0.1, -0.2, 1.2));
  const Eigen::Vector3d p_T2inT(0.3, -0.4, 0.2);
  const TargetInImu ti = true_target_in_imu(t0);
  const Eigen::Matrix3d R_ItoT = quat_to_rot(ti.q_ItoT);
  const Eigen::Vector4d q_ItoT2 = rot_to_quat(R_TtoT2 * R_ItoT);
  const Eigen::Vector3d p_T2inI = ti.p_TinI + R_ItoT.transpose() * p_T2inT;

  const TargetFrameTransform X = target_frame_transform(t0, q_ItoT2, p_T2inI);
  CHECK(orientation_error(X.q_TtoTest, rot_to_quat(R_TtoT2)).norm() < 1e-12);
  CHECK((X.p_TestInT - p_T2inT).norm() < 1e-12);
  CHECK(std::abs(X.angle_deg() - Eigen::AngleAxisd(R_TtoT2).angle() * 180.0 / M_PI) < 1e-9);
  CHECK_FALSE(X.is_identity());

  // At the start the truth of the filter's frame is the estimate.
  const TargetInImu e0 = true_target_in_imu(in_target_frame(t0, X));
  CHECK(orientation_error(e0.q_ItoT, q_ItoT2).norm() < 1e-12);
  CHECK((e0.p_TinI - p_T2inI).norm() < 1e-12);

  // Later: the body point p_T2inT of the true frame, with its velocity
  // (finite difference of its world position) expressed in the filter's frame.
  const double t = 2.0, h = 1e-5;
  const GroundTruth g = in_target_frame(truth_at(t), X);
  auto point_in_G = [&](double s) {
    const GroundTruth a = truth_at(s);
    return Eigen::Vector3d(a.p_TinG + quat_to_rot(a.q_GtoT).transpose() * p_T2inT);
  };
  CHECK((g.p_TinG - point_in_G(t)).norm() < 1e-12);
  CHECK(orientation_error(g.q_GtoT, rot_to_quat(R_TtoT2 * quat_to_rot(truth_at(t).q_GtoT))).norm() < 1e-12);
  const Eigen::Vector3d v_G = (point_in_G(t + h) - point_in_G(t - h)) / (2.0 * h);
  CHECK((quat_to_rot(g.q_GtoT).transpose() * g.v_TinT - v_G).norm() < 1e-7);
  CHECK((quat_to_rot(g.q_GtoT).transpose() * g.w_TinT - Eigen::Vector3d(0.0, 0.0, 0.4)).norm() < 1e-12);
}

TEST_CASE("target frame transform: identity leaves the truth untouched", "[eval][target]") {
  const TargetFrameTransform X;
  CHECK(X.is_identity());
  const GroundTruth t = truth_at(1.0);
  const GroundTruth u = in_target_frame(t, X);
  CHECK(u.q_GtoT == t.q_GtoT);  // bit-identical: the start from the truth keeps its figures
  CHECK(u.p_TinG == t.p_TinG);
  CHECK(u.v_TinT == t.v_TinT);
  // A filter started exactly at the truth gets the identity (up to round-off).
  const TargetInImu ti = true_target_in_imu(t);
  const TargetFrameTransform Y = target_frame_transform(t, ti.q_ItoT, ti.p_TinI);
  CHECK(Y.angle_deg() < 1e-9);
  CHECK(Y.p_TestInT.norm() < 1e-12);
}

// A target filter that restarts (a respawned process) defines a new frame of
// its own: with a restart gap the matcher takes the frame again after it.
TEST_CASE("target restarts: the frame is taken again after a gap in the target states", "[eval][target]") {
  TargetFrameTransform first, second;
  first.q_TtoTest = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, 0.7)));
  first.p_TestInT = Eigen::Vector3d(0.2, -0.1, 0.3);
  second.q_TtoTest = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, -1.1)));
  second.p_TestInT = Eigen::Vector3d(-0.3, 0.4, 0.0);
  TruthMatcher matcher;
  for (int k = 0; k <= 40; ++k) matcher.add_truth(truth_at(0.1 * k));
  for (int k = 0; k <= 10; ++k) matcher.add_target(exact_estimate(0.1 * k, first));   // 0 .. 1 s
  for (int k = 25; k <= 40; ++k) matcher.add_target(exact_estimate(0.1 * k, second)); // after a 1.5 s gap

  TargetMatchCounts counts;
  const TargetMatch again = matcher.match_targets(&counts, /*own_frame=*/true, /*restart_gap_us=*/500000);
  REQUIRE(counts.matched == 27);
  CHECK(again.frame_restarts == 1);
  CHECK(orientation_error(again.target_frame.q_TtoTest, second.q_TtoTest).norm() < 1e-9);
  for (const ErrorSample& e : again.target_in_world) {
    CHECK(e.err_p.norm() < 1e-9);
    CHECK(e.err_theta.norm() < 1e-9);
  }
  // Taken once, the second run's states are compared in the wrong frame.
  const TargetMatch once = matcher.match_targets(&counts, /*own_frame=*/true);
  CHECK(once.frame_restarts == 0);
  CHECK(once.target_in_world.front().err_p.norm() < 1e-9);
  CHECK(once.target_in_world.back().err_p.norm() > 0.1);
}

// The target filter started its target again (adaptive.restart) in the same
// process: no gap, but a new start_count, and the matcher takes the frame
// again at the first state of the new start.
TEST_CASE("target restarts: the frame is taken again when start_count changes", "[eval][target]") {
  TargetFrameTransform first, second;
  first.q_TtoTest = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, 0.4)));
  first.p_TestInT = Eigen::Vector3d(0.1, 0.2, -0.1);
  second.q_TtoTest = rot_to_quat(exp_so3(Eigen::Vector3d(0.0, 0.0, 0.45)));
  second.p_TestInT = Eigen::Vector3d(0.15, 0.2, -0.1);  // 5 cm from the first, along x
  TruthMatcher matcher;
  for (int k = 0; k <= 40; ++k) {
    matcher.add_truth(truth_at(0.1 * k));
    matcher.add_target(k <= 20 ? exact_estimate(0.1 * k, first, 1) : exact_estimate(0.1 * k, second, 2));
  }
  TargetMatchCounts counts;
  // A gap bound far above the 0.1 s between states: only start_count tells.
  const TargetMatch m = matcher.match_targets(&counts, /*own_frame=*/true, /*restart_gap_us=*/500000);
  REQUIRE(counts.matched == 41);
  CHECK(m.frame_restarts == 1);
  CHECK(orientation_error(m.target_frame.q_TtoTest, second.q_TtoTest).norm() < 1e-9);
  CHECK((m.target_frame.p_TestInT - second.p_TestInT).norm() < 1e-9);
  for (const ErrorSample& e : m.target_in_imu) {
    CHECK(e.err_p.norm() < 1e-9);
    CHECK(e.err_theta.norm() < 1e-9);
  }
}

// Scale estimator on synthetic analytic motions (default options, N_o = 200,
// n = 1, 20 Hz): the normal case is accepted with the true scale; the
// degenerate cases of the paper's Table I are rejected by the sub-condition
// the paper names:
//   C1 camera translates exactly as the object  -> (i)   f(s*) <= eps_t1 fails
//   C2 camera static                             -> (ii)  sum Cov^2(m_c,m_c) >= rho_t1 fails
//   C3 camera at constant velocity               -> (ii)
//   C4 object static in the camera frame while
//      both move                                 -> (iii) sum Cov^2(m_d,m_c) >= rho_t2 fails
#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <string>

#include "scale_scenarios.h"

using namespace vimot;
using namespace vimot::scale;
using namespace vimot::scale::testing;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kScale = 2.5;  // true s: p_OinC = s * pbar_OinC

std::string describe(const ScaleResult& r) {
  std::ostringstream os;
  os << "scale " << r.scale << " f " << r.f_value << " f_rel " << r.f_relative << " (ii) "
     << r.condition[1] << " (iii) " << r.condition[2] << " ok " << r.condition_ok[0]
     << r.condition_ok[1] << r.condition_ok[2] << " failed " << r.failed_condition;
  return os.str();
}

// The camera attitude of normal_camera() at t = 0 (optical axis ~ world +x).
Eigen::Matrix3d R0_camera() { return normal_camera(0.0).R_XtoG; }

}  // namespace

TEST_CASE("scale_scenarios: normal case, noise-free, accepted with the true scale", "[scale]") {
  ScaleEstimator est;
  int accepted = 0;
  ScaleResult r;
  // 400 observations: the estimate is made every frame once the window is full.
  for (const ScaleObservation& o : generate(normal_camera, normal_object, kScale, 400)) {
    REQUIRE(est.add(o) == AddStatus::kAdded);
    r = est.update();
    if (est.window().size() < 200) {
      CHECK(r.status == ScaleStatus::kInsufficientData);
      continue;
    }
    INFO(describe(r));
    CHECK(r.accepted);
    CHECK_THAT(r.scale, WithinRel(kScale, 1e-9));
    accepted += r.accepted;
  }
  INFO(describe(r));
  CHECK(accepted == 201);
  CHECK(r.num_observations == 200);
  CHECK(r.num_motion_samples == 198);
  CHECK(r.f_value < 1e-20);
  CHECK(r.condition[1] > 100 * est.options().rho_t1);
  CHECK(r.condition[2] > 100 * est.options().rho_t2);

  // Eq. 20-21 recover the true metric object pose.
  const double t = 399 * kDt;
  const Pose truth = normal_object(t);
  const auto pose = est.latest_object_pose();
  REQUIRE(pose);
  CHECK((pose->p_OinG - truth.p_XinG).norm() < 1e-8);
  CHECK(rotation_angle_between(pose->R_OtoG, truth.R_XtoG) < 1e-9);
  CHECK(rotation_angle_between(quat_to_rot(pose->q_GtoO), truth.R_XtoG.transpose()) < 1e-9);
  CHECK((pose->p_OinC - normal_camera(t).R_XtoG.transpose() * (truth.p_XinG - normal_camera(t).p_XinG))
            .norm() < 1e-8);
}

TEST_CASE("scale_scenarios: normal case with n = 2 (acceleration)", "[scale]") {
  ScaleEstimatorOptions o;
  o.derivative_order = 2;
  // (m/s^2)^4 units: the same excitation levels are larger by ~(2 pi f)^4.
  o.epsilon_t1 = 1e-3;
  o.rho_t1 = 1e-1;
  o.rho_t2 = 1e-2;
  ScaleEstimator est(o);
  const ScaleResult r = run(est, generate(normal_camera, normal_object, kScale, 250));
  INFO(describe(r));
  CHECK(r.accepted);
  CHECK_THAT(r.scale, WithinRel(kScale, 1e-9));
}

TEST_CASE("scale_scenarios: normal case with jittered utimes and small noise, within 2%", "[scale]") {
  Noise n;
  n.jitter_s = 0.002;         // non-uniform timestamps, +-2 ms
  n.sigma_pbar = 0.002;       // tracker: 0.002 units = 5 mm at s = 2.5
  n.sigma_p_cam = 0.001;      // VINS: 1 mm
  n.sigma_theta_cam = 0.001;  // VINS: 0.06 deg
  for (unsigned seed = 1; seed <= 5; ++seed) {
    n.seed = seed;
    ScaleEstimator est;
    const ScaleResult r = run(est, generate(normal_camera, normal_object, kScale, 300, 0, n));
    INFO("seed " << seed << ": " << describe(r));
    CHECK(r.accepted);
    CHECK_THAT(r.scale, WithinRel(kScale, 0.02));
    const auto pose = est.latest_object_pose();
    REQUIRE(pose);
    CHECK((pose->p_OinG - normal_object(299 * kDt).p_XinG).norm() < 0.02 * 4.5);
  }
}

TEST_CASE("scale_scenarios: C1 camera translating exactly as the object -> (i) fails", "[scale]") {
  // p_CinG(t) = p_OinG(t) - r, r constant; the camera still rotates. Then
  // p_d^w = R_CtoG pbar_OinC = r / s is constant: m_d = 0, D = 0, and
  // f(s) = sum C^2 for every s, far above eps_t1 (Eq. 15: Cov(m_o, m_c) =
  // Cov(m_c, m_c) does not go to 0).
  const Motion cam = [](double t) {
    Pose p = normal_camera(t);
    p.p_XinG = normal_object(t).p_XinG - Eigen::Vector3d(4.0, 1.0, 0.0);
    return p;
  };
  {
    ScaleEstimator est;
    const ScaleResult r = run(est, generate(cam, normal_object, kScale, 200));
    INFO(describe(r));
    CHECK_FALSE(r.accepted);
    CHECK(r.failed_condition == 1);
    CHECK_FALSE(r.condition_ok[0]);
    CHECK(r.condition_ok[1]);  // the camera is well excited
    // D = 0 up to rounding: (iii) fails as well, s* is meaningless
    // (NaN for an exact D = 0, huge here).
    CHECK_FALSE(r.condition_ok[2]);
    CHECK_FALSE(std::abs(r.scale) < 1e3);
    CHECK(!est.has_scale());
  }
  {  // With tracker / VINS noise, m_d is noise only: s* is erratic (Table I),
     // f(s*) stays near sum C^2.
    Noise n;
    n.sigma_pbar = 0.002;
    n.sigma_p_cam = 0.001;
    n.sigma_theta_cam = 0.001;
    for (unsigned seed = 1; seed <= 3; ++seed) {
      n.seed = seed;
      ScaleEstimator est;
      const ScaleResult r = run(est, generate(cam, normal_object, kScale, 200, 0, n));
      INFO("seed " << seed << ": " << describe(r));
      CHECK_FALSE(r.accepted);
      CHECK(r.failed_condition == 1);
      CHECK(r.f_relative > 0.5);
    }
  }
}

TEST_CASE("scale_scenarios: C2 camera static -> (ii) fails", "[scale]") {
  const Motion cam = [](double) {
    Pose p;
    p.R_XtoG = R0_camera();
    p.p_XinG = Eigen::Vector3d(0.5, -0.2, 1.0);
    return p;
  };
  {
    ScaleEstimator est;
    const ScaleResult r = run(est, generate(cam, normal_object, kScale, 200));
    INFO(describe(r));
    CHECK_FALSE(r.accepted);
    CHECK(r.failed_condition == 2);
    CHECK(r.condition_ok[0]);  // f(s*) <= sum C^2 = 0
    CHECK_FALSE(r.condition_ok[1]);
  }
  {  // With VINS noise: s* near 0 (Table I), still (ii).
    Noise n;
    n.sigma_pbar = 0.002;
    n.sigma_p_cam = 0.001;
    n.sigma_theta_cam = 0.001;
    ScaleEstimator est;
    const ScaleResult r = run(est, generate(cam, normal_object, kScale, 200, 0, n));
    INFO(describe(r));
    CHECK_FALSE(r.accepted);
    CHECK(r.failed_condition == 2);
    CHECK(std::abs(r.scale) < 0.5 * kScale);
  }
}

TEST_CASE("scale_scenarios: C3 camera at constant velocity -> (ii) fails", "[scale]") {
  // Constant velocity (the camera may rotate): m_c is constant, C = 0.
  const Motion cam = [](double t) {
    Pose p = normal_camera(t);
    p.p_XinG = Eigen::Vector3d(-1.0 + 0.4 * t, 0.2 - 0.3 * t, 0.1 * t);
    return p;
  };
  for (int n : {1, 2}) {
    ScaleEstimatorOptions o;
    o.derivative_order = n;
    ScaleEstimator est(o);
    const ScaleResult r = run(est, generate(cam, normal_object, kScale, 200));
    INFO("n = " << n << ": " << describe(r));
    CHECK_FALSE(r.accepted);
    CHECK(r.failed_condition == 2);
    CHECK(r.condition_ok[0]);
    CHECK_FALSE(r.condition_ok[1]);
  }
}

namespace {

// A large platform (e.g. a ship deck) yawing about the vertical axis through
// the origin, theta(t) non-uniform. The camera rides on it 50 m from the
// axis looking towards it; the object rides on it 3 m in front of the
// camera. The object is therefore static in the camera frame while both
// move in the world.
double platform_yaw(double t, double amp) {
  return amp * (harmonic(t, 2) + 0.5 * harmonic(t, 3, 0.5));
}

Pose platform_camera(double t, double radius, double amp = 0.02) {
  const Eigen::Matrix3d Rz = exp_so3(Eigen::Vector3d(0, 0, platform_yaw(t, amp)));
  Pose p;
  p.p_XinG = Rz * Eigen::Vector3d(-radius, 0.0, 1.5);
  p.R_XtoG = Rz * R0_camera();  // optical axis towards the yaw axis (+x)
  return p;
}

Pose platform_object(double t, double radius, double depth, double amp = 0.02) {
  const Eigen::Matrix3d Rz = exp_so3(Eigen::Vector3d(0, 0, platform_yaw(t, amp)));
  Pose p;
  p.p_XinG = Rz * Eigen::Vector3d(-radius + depth, 0.0, 1.5);
  p.R_XtoG = Rz;
  return p;
}

}  // namespace

TEST_CASE("scale_scenarios: C4 object static in the camera frame, both moving -> (iii) fails",
          "[scale]") {
  // With pbar_OinC constant, m_d = d/dt(R_CtoG) pbar is produced by the
  // platform yaw only. Here m_d = -m_c / R (R = 50 m, tracker unit = the
  // 3 m depth, s = 3): D = -C / R, so f(s*) = 0 and (i) passes, (ii) passes,
  // but sum D^2 = sum C^2 / R^2 is tiny and (iii) fails. s* = R = 50, far
  // from s = 3, like the large values of Table I.
  const double radius = 50.0, depth = 3.0;
  const Motion cam = [&](double t) { return platform_camera(t, radius); };
  const Motion obj = [&](double t) { return platform_object(t, radius, depth); };
  ScaleEstimator est;
  const ScaleResult r = run(est, generate(cam, obj, depth, 200));
  INFO(describe(r));
  CHECK_FALSE(r.accepted);
  CHECK(r.failed_condition == 3);
  CHECK(r.condition_ok[0]);
  CHECK(r.condition_ok[1]);
  CHECK_FALSE(r.condition_ok[2]);
  CHECK_THAT(r.scale, WithinRel(radius, 1e-6));
  CHECK_THAT(r.condition[2], WithinRel(r.condition[1] / (radius * radius), 1e-6));
}

TEST_CASE("scale_scenarios: C4 without camera rotation is C1 (m_d = 0): (i) and (iii) fail",
          "[scale]") {
  // Object rigidly carried in front of a translating, non-rotating camera:
  // p_d^w constant, D = 0: f = sum C^2 (first failure (i)), sum D^2 = 0.
  const Motion cam = [](double t) {
    Pose p = normal_camera(t);
    p.R_XtoG = R0_camera();
    return p;
  };
  const Motion obj = [](double t) {
    Pose p = normal_camera(t);
    p.p_XinG += Eigen::Vector3d(3.0, 0.2, -0.1);
    p.R_XtoG = Eigen::Matrix3d::Identity();
    return p;
  };
  ScaleEstimator est;
  const ScaleResult r = run(est, generate(cam, obj, kScale, 200));
  INFO(describe(r));
  CHECK_FALSE(r.accepted);
  CHECK(r.failed_condition == 1);
  CHECK_FALSE(r.condition_ok[0]);
  CHECK_FALSE(r.condition_ok[2]);
}

TEST_CASE("scale_scenarios: coupled motion giving s* < 0 passes Eq. 19, rejected by the sign check",
          "[scale]") {
  // Same platform, camera 2 m from the axis looking outwards at an object
  // 3 m further out: m_d = +m_c / R, so s* = -R, f(s*) = 0 and sum D^2 is
  // large. All three sub-conditions of Eq. 19 hold; only s* > 0 (vimot)
  // rejects it.
  const double radius = 2.0, depth = 3.0;
  // Yaw amplitude 0.2 rad so that (ii) holds at a 2 m radius.
  const Motion cam = [&](double t) {
    Pose p = platform_camera(t, radius, 0.2);
    p.R_XtoG = p.R_XtoG * exp_so3(Eigen::Vector3d(0, M_PI, 0));  // look outwards (-x)
    return p;
  };
  const Motion obj = [&](double t) { return platform_object(t, radius, -depth, 0.2); };
  ScaleEstimatorOptions o;
  ScaleEstimator est(o);
  const ScaleResult r = run(est, generate(cam, obj, depth, 200));
  INFO(describe(r));
  CHECK(r.condition_ok == std::array<bool, 3>{{true, true, true}});
  CHECK_THAT(r.scale, WithinRel(-radius, 1e-6));
  CHECK_FALSE(r.scale_positive_ok);
  CHECK(r.failed_condition == 4);
  CHECK_FALSE(r.accepted);

  o.require_positive_scale = false;  // the paper's Eq. 19 alone accepts it
  ScaleEstimator est2(o);
  CHECK(run(est2, generate(cam, obj, depth, 200)).accepted);
}

TEST_CASE("scale_scenarios: the last accepted scale is held until a new one is accepted",
          "[scale]") {
  ScaleEstimator est;
  ScaleResult r = run(est, generate(normal_camera, normal_object, kScale, 200));
  REQUIRE(r.accepted);
  // The camera stops (C2) right after: every new estimate is rejected, the
  // held scale stays and is still applied to the new observations.
  const Pose stop = normal_camera(200 * kDt);
  const Motion still = [&](double) { return stop; };
  // (Mixed windows right after the stop may still be accepted; whatever
  // happens, a rejection never changes the held scale.)
  int rejected_tail = 0;
  int k = 0;
  for (const ScaleObservation& o : generate(still, normal_object, kScale, 200, 200)) {
    REQUIRE(est.add(o) == AddStatus::kAdded);
    const double held = est.scale();
    r = est.update();
    if (r.accepted) {
      CHECK(est.scale() == r.scale);
    } else {
      CHECK(est.scale() == held);
      if (k >= 100) ++rejected_tail;
    }
    ++k;
  }
  INFO(describe(r));
  CHECK(rejected_tail == 100);  // once the window is mostly static: (ii) fails
  CHECK(r.failed_condition == 2);
  CHECK_THAT(est.scale(), WithinRel(kScale, 0.05));
  const auto pose = est.latest_object_pose();
  REQUIRE(pose);
  CHECK(pose->scale == est.scale());
  CHECK((pose->p_OinG - object_pose_in_world(est.scale(), est.window().back()).p_OinG).norm() == 0.0);

  // After a tracking gap (window cleared, scale held) the tracker restarts
  // with another unit (s = 4): the new scale replaces the old one once the
  // new window is accepted.
  const double held = est.scale();
  const auto fresh = generate(normal_camera, normal_object, 4.0, 200, 500);
  CHECK(est.add(fresh.front()) == AddStatus::kAddedAfterGap);
  CHECK(est.window().size() == 1);
  CHECK(est.scale() == held);
  for (size_t k = 1; k < fresh.size(); ++k) {
    est.add(fresh[k]);
    r = est.update();
  }
  CHECK(r.accepted);
  CHECK_THAT(est.scale(), WithinRel(4.0, 1e-9));
}

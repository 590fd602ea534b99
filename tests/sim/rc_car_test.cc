// The paper scenario's rc_car target (config/sim_paper_rc_car.yaml,
// common/sim/rc_car_course.h): the course itself, then the target spline the
// simulator builds from it and the UAV that follows it. The statistics the
// second test prints are those of docs/simulator.md.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "common/sim/rc_car_course.h"
#include "common/sim/simulator.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

SimConfig rc_car_config() { return test::load_config("config/sim_paper_rc_car.yaml"); }

}  // namespace

TEST_CASE("RcCarCourse: a seeded course of the semicircle's length and turn, with stops", "[sim][rc_car]") {
  const SimConfig c = rc_car_config();
  const RcCarConfig& rc = c.paper.rc_car;
  const RcCarCourse course(rc, 50.0, 0.0, 0.5, 7);
  CHECK(course.length() == Approx(M_PI * 50.0));
  CHECK(course.distance(course.duration()) == Approx(course.length()).epsilon(1e-12));
  // Turns by π in all, so it ends heading back as the semicircle does.
  CHECK(course.heading(course.length()) - course.heading(0.0) == Approx(M_PI).epsilon(1e-12));
  CHECK(course.heading(0.0) == Approx(0.5 * M_PI));
  CHECK(course.distance(-1.0) == 0.0);
  CHECK(course.speed(0.0) == 0.0);  // starts from rest

  // Speed within [0, speed_max], stops inside the run, cruising over most of
  // [speed_min, speed_max]; the distance is the integral of the speed.
  double v_max = 0.0, stopped = 0.0, s_integral = 0.0;
  double v_cruise_min = rc.speed_max;
  const double dt = 1e-3;
  for (double t = dt; t <= course.duration(); t += dt) {
    const double v = course.speed(t);
    CHECK(v >= 0.0);
    v_max = std::max(v_max, v);
    if (v == 0.0) stopped += dt;
    // Cruising: the speed held over the next half second.
    if (v > 0.0 && std::abs(course.speed(t + 0.5) - v) < 1e-12) v_cruise_min = std::min(v_cruise_min, v);
    s_integral += 0.5 * dt * (course.speed(t - dt) + v);
  }
  CHECK(v_max <= rc.speed_max);
  CHECK(v_max > rc.speed_max - 0.5);
  CHECK(v_cruise_min < rc.speed_min + 0.5);
  CHECK(stopped > rc.stop_min);
  CHECK(s_integral == Approx(course.distance(std::floor(course.duration() / dt) * dt)).epsilon(1e-6));

  // Position is the integral of the heading's tangent: finite differences of
  // the pose along the path give the heading.
  for (double t = 1.0; t < course.duration(); t += 3.7) {
    const double h = 1e-4;
    if (course.speed(t) < 0.1) continue;
    const Eigen::Vector3d d = course.pose(t + h).topRightCorner<3, 1>() - course.pose(t - h).topRightCorner<3, 1>();
    const double yaw = course.heading(course.distance(t));
    CHECK(std::remainder(std::atan2(d.y(), d.x()) - yaw, 2.0 * M_PI) == Approx(0.0).margin(1e-6));
    CHECK(d.norm() / (2 * h) == Approx(course.speed(t)).epsilon(1e-6));
  }

  // Deterministic for its seed, another seed another course.
  const RcCarCourse same(rc, 50.0, 0.0, 0.5, 7), other(rc, 50.0, 0.0, 0.5, 8);
  CHECK(same.duration() == course.duration());
  CHECK(same.pose(30.0) == course.pose(30.0));
  CHECK((other.pose(30.0) - course.pose(30.0)).norm() > 0.1);
}

TEST_CASE("Paper scenario, rc_car target: exact spline derivatives, planar, speed range, UAV following",
          "[sim][rc_car]") {
  const SimConfig c = rc_car_config();
  const RcCarConfig& rc = c.paper.rc_car;
  Simulator sim(c);
  REQUIRE(sim.has_target());
  const double h_T = c.target.base_height + 0.5 * c.target.size.z();
  // Starts where the semicircle starts; the course is drawn from map_seed.
  CHECK((sim.target_state(0.0)->p_BinG - Eigen::Vector3d(50.0, 0.0, h_T)).norm() < 0.01);
  const RcCarCourse course(rc, c.paper.radius, c.paper.target_start_angle, h_T, derive_seed(c.map_seed, 14));
  CHECK(sim.duration() == Approx(course.duration()).margin(1e-6));  // whole µs

  // The UAV camera sits `standoff` behind along the heading, lateral_offset
  // to the left, `height` up, plus the oscillation: its distance to the
  // target is at most the norm of those offsets with every amplitude added.
  const Eigen::Vector3d amp = c.paper.oscillation.amplitude;
  const double max_distance = Eigen::Vector3d(c.paper.standoff + amp.x(), std::abs(c.paper.lateral_offset) + amp.y(),
                                              c.paper.height + amp.z() - h_T)
                                  .norm();
  double v_min = 1e9, v_max = 0.0, v_sum = 0.0, a_tan_max = 0.0, a_lat_max = 0.0, w_min = 1e9, w_max = -1e9;
  double k_min = 1e9, k_max = -1e9;  // curvature ω_z / speed while moving
  Eigen::AlignedBox2d extent;
  double stopped = 0.0, max_slip = 0.0, max_cam_angle = 0.0, max_distance_seen = 0.0, imu_w_max = 0.0,
         imu_a_max = 0.0;
  int n = 0;
  // Steps of the first and second differences: the course lies 50 m from the
  // origin, and the spline's pose carries ~1e-10 m of round-off where the
  // rotation between control poses is tiny (near-straight stretches), which
  // a 1e-4 s second difference would amplify to 1e-2 m/s².
  const double step = 0.01, h = 1e-5, h2 = 1e-3;
  for (double t = 2 * h2; t <= sim.duration() - 2 * h2; t += step) {
    const SplineState T = *sim.target_state(t);
    // Exact derivatives: the analytic v, a, ω, α against central differences
    // of the spline's own pose.
    const SplineState Tm = *sim.target_state(t - h), Tp = *sim.target_state(t + h);
    const Eigen::Vector3d v_fd = (Tp.p_BinG - Tm.p_BinG) / (2 * h);
    CHECK((T.v_BinG - v_fd).norm() < 1e-6 * (1.0 + v_fd.norm()));
    const Eigen::Vector3d a_fd =
        (sim.target_state(t + h2)->p_BinG - 2.0 * T.p_BinG + sim.target_state(t - h2)->p_BinG) / (h2 * h2);
    CHECK((T.a_BinG - a_fd).norm() < 1e-3 * (1.0 + a_fd.norm()));  // round-off / h2² ≈ 1e-4
    const Eigen::Matrix3d W = T.R_BtoG.transpose() * (Tp.R_BtoG - Tm.R_BtoG) / (2 * h);
    CHECK((T.w_BinB - Eigen::Vector3d(W(2, 1), W(0, 2), W(1, 0))).norm() < 1e-6 * (1.0 + T.w_BinB.norm()));
    const Eigen::Vector3d alpha_fd = (Tp.w_BinB - Tm.w_BinB) / (2 * h);
    CHECK((T.alpha_BinB - alpha_fd).norm() < 1e-5 * (1.0 + alpha_fd.norm()));

    // Planar: the box centre's plane, yaw only, no vertical velocity or tilt rate.
    CHECK(T.p_BinG.z() == Approx(h_T).margin(1e-9));
    CHECK((T.R_BtoG.col(2) - Eigen::Vector3d::UnitZ()).norm() < 1e-9);
    CHECK(std::abs(T.v_BinG.z()) < 1e-9);
    CHECK(T.w_BinB.head<2>().norm() < 1e-9);

    extent.extend(Eigen::Vector2d(T.p_BinG.head<2>()));
    const Eigen::Vector3d v_T = T.R_BtoG.transpose() * T.v_BinG;  // body velocity
    const double speed = T.v_BinG.norm();
    if (speed < 1e-9) stopped += step;
    // Heading along the path: the sideways body velocity against the speed.
    max_slip = std::max(max_slip, std::abs(v_T.y()) / std::max(speed, 0.1));
    v_min = std::min(v_min, speed);
    v_max = std::max(v_max, speed);
    v_sum += speed;
    ++n;
    const Eigen::Vector3d a_T = T.R_BtoG.transpose() * T.a_BinG;
    a_tan_max = std::max(a_tan_max, std::abs(a_T.x()));
    a_lat_max = std::max(a_lat_max, std::abs(a_T.y()));
    if (speed > 0.3) {
      k_min = std::min(k_min, T.w_BinB.z() / speed);
      k_max = std::max(k_max, T.w_BinB.z() / speed);
    }
    w_min = std::min(w_min, T.w_BinB.z());
    w_max = std::max(w_max, T.w_BinB.z());

    // The UAV keeps the target within its standoff and on its optical axis.
    Eigen::Matrix3d R_CtoG;
    Eigen::Vector3d p_C;
    test::cam0_in_G(sim, t, &R_CtoG, &p_C);
    const Eigen::Vector3d to_target = T.p_BinG - p_C;
    max_distance_seen = std::max(max_distance_seen, to_target.norm());
    max_cam_angle = std::max(max_cam_angle, std::acos(std::min(1.0, R_CtoG.col(2).dot(to_target.normalized()))));
    const SplineState I = sim.robot_state(t);
    imu_w_max = std::max(imu_w_max, I.w_BinB.norm());
    imu_a_max = std::max(imu_a_max, I.a_BinG.norm());
  }
  std::printf(
      "rc_car (map_seed %d): %.2f s, %.1f m, x %.1f..%.1f y %.1f..%.1f m, end (%.1f, %.1f); target speed %.3f-%.3f m/s (mean %.3f), stopped %.1f s; "
      "|a| tangential <= %.3f, lateral <= %.3f m/s^2; turn rate %.4f..%.4f rad/s; curvature %.4f..%.4f 1/m; side slip <= %.2e of the speed; "
      "UAV: camera-target distance <= %.2f m (bound %.2f), optical axis off the target <= %.4f deg, "
      "IMU |w| <= %.3f rad/s, |a| <= %.3f m/s^2\n",
      static_cast<int>(c.map_seed), sim.duration(), course.length(), extent.min().x(), extent.max().x(),
      extent.min().y(), extent.max().y(), sim.target_state(sim.duration())->p_BinG.x(),
      sim.target_state(sim.duration())->p_BinG.y(), v_min, v_max, v_sum / n, stopped, a_tan_max,
      a_lat_max, w_min, w_max, k_min, k_max, max_slip, max_distance_seen, max_distance, max_cam_angle * 180.0 / M_PI, imu_w_max,
      imu_a_max);
  // The spline stays within the course's speed range (it averages control
  // poses) and reproduces its stops exactly (equal control poses).
  CHECK(v_max <= rc.speed_max * 1.01);
  CHECK(v_max > rc.speed_max - 0.5);
  CHECK(stopped > rc.stop_min);
  CHECK(a_tan_max <= rc.max_acceleration * 1.05);
  // The spline blends twists, which couples rotation into translation at
  // second order: sideways velocity ~ (ω dt)² ≈ (0.12 rad/s · 0.1 s)² of the speed.
  CHECK(max_slip < 1e-3);
  CHECK(max_distance_seen <= max_distance);
  CHECK(max_cam_angle < 1e-3);

  // The target is in view of both cameras in every frame.
  int frames = 0;
  sim.run([&](const SimEvent& e) {
    if (const auto* f = std::get_if<CameraFrame>(&e)) {
      int target[2] = {0, 0};
      for (const auto& o : f->observations) {
        if (o.is_target) ++target[o.camera_id];
      }
      CHECK(target[0] >= 30);
      CHECK(target[1] >= 30);
      ++frames;
    }
  });
  CHECK(frames == sim.camera_frame_count());
}

TEST_CASE("paper.target_motion and paper.rc_car: read, and bad values named", "[sim][rc_car]") {
  const SimConfig c = rc_car_config();
  CHECK(c.paper.target_motion == TargetMotion::kRcCar);
  CHECK(c.paper.rc_car.speed_min == 0.5);
  CHECK(c.paper.rc_car.speed_max == 2.5);
  CHECK(test::paper_config().paper.target_motion == TargetMotion::kSemicircle);
  SimConfig bad = c;
  bad.paper.rc_car.speed_min = 0.0;
  CHECK_THROWS_WITH(validate(bad), Catch::Contains("paper.rc_car.speed_range"));
  bad = c;
  bad.paper.rc_car.stop_probability = 1.0;
  CHECK_THROWS_WITH(validate(bad), Catch::Contains("paper.rc_car.stop_probability"));
  bad = c;
  bad.paper.rc_car.max_acceleration = std::nan("");
  CHECK_THROWS_WITH(validate(bad), Catch::Contains("paper.rc_car.max_acceleration"));
  bad = c;
  bad.paper.rc_car.heading_deviation = 2.0;
  CHECK_THROWS_WITH(validate(bad), Catch::Contains("paper.rc_car.heading_deviation"));
  CHECK_THROWS_WITH(target_motion_from_string("bicycle"), Catch::Contains("semicircle or rc_car"));
}

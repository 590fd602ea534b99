#include "common/sim/scenarios.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/math/quat.h"
#include "common/sim/rc_car_course.h"
#include "common/sim/trajectory_file.h"

namespace vimot {
namespace sim {

namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// OpenVINS's lower bound on the control pose spacing of a fitted file.
constexpr double kMinFileSplineDt = 0.05;
// Spacing (s) at which spline positions are sampled for workspace bounds.
constexpr double kBoundsSampleDt = 0.5;
// Random stream of the rc_car course, from map_seed (derive_seed; the
// simulator's other streams are 10-13).
constexpr uint64_t kStreamCourse = 14;

std::string fmt(double v) {
  std::ostringstream ss;
  ss.precision(10);
  ss << v;
  return ss.str();
}

Eigen::Matrix3d rot_z(double yaw) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

// Floor rectangle covering the spline positions of both bodies, grown by margin.
Eigen::AlignedBox2d bounds_of(const BsplineSE3& a, const std::optional<BsplineSE3>& b, double t_begin,
                              double duration, double margin) {
  Eigen::AlignedBox2d box;
  const int n = std::max(2, static_cast<int>(std::ceil(duration / kBoundsSampleDt)) + 1);
  for (int k = 0; k < n; ++k) {
    const double t = t_begin + duration * static_cast<double>(k) / static_cast<double>(n - 1);
    box.extend(Eigen::Vector2d(a.pose(t).block<2, 1>(0, 3)));
    if (b) box.extend(Eigen::Vector2d(b->pose(t).block<2, 1>(0, 3)));
  }
  box.min().array() -= margin;
  box.max().array() += margin;
  return box;
}

double target_center_height(const TargetConfig& target) { return target.base_height + 0.5 * target.size.z(); }

ScenarioMotion make_paper(const SimConfig& config) {
  const PaperScenarioConfig& pc = config.paper;
  const CameraCalibration& cam0 = config.camera.calibrations.at(0);
  const double h_T = target_center_height(config.target);
  std::optional<RcCarCourse> course;
  if (pc.target_motion == TargetMotion::kRcCar) {
    course.emplace(pc.rc_car, pc.radius, pc.target_start_angle, h_T, derive_seed(config.map_seed, kStreamCourse));
  }
  // Splines and workspace cover at least the whole course, so a shorter run
  // is an exact prefix of the full one (same map, same events).
  const double natural = course ? course->duration() : M_PI * pc.radius / pc.speed;
  const double duration = config.duration > 0.0 ? config.duration : natural;
  const double span = std::max(duration, natural);

  // Polar angle of the semicircle's target at time t (counter-clockwise).
  auto angle = [&pc](double t) { return pc.target_start_angle + pc.speed * t / pc.radius; };
  auto target_position = [&pc, &angle, h_T](double t) {
    const double th = angle(t);
    return Eigen::Vector3d(pc.radius * std::cos(th), pc.radius * std::sin(th), h_T);
  };
  auto target_pose = [&](double t) {
    if (course) return course->pose(t);
    // Heading along the tangent: yaw = θ + π/2, T's x axis forward.
    return make_se3(rot_z(angle(t) + 0.5 * M_PI), target_position(t));
  };
  // Unit path tangent (the target's heading) at time t.
  auto tangent_at = [&](double t) {
    if (course) {
      const double yaw = course->heading(course->distance(t));
      return Eigen::Vector3d(std::cos(yaw), std::sin(yaw), 0.0);
    }
    const double th = angle(t);
    return Eigen::Vector3d(-std::sin(th), std::cos(th), 0.0);
  };
  auto robot_pose = [&](double t) {
    const Eigen::Vector3d tangent = tangent_at(t);
    const Eigen::Vector3d left = Eigen::Vector3d::UnitZ().cross(tangent);
    const Eigen::Vector3d osc = eval_sinusoids({pc.oscillation}, t);
    const Eigen::Vector3d p_T = target_pose(t).topRightCorner<3, 1>();
    Eigen::Vector3d p_C = p_T + (osc.x() - pc.standoff) * tangent + (pc.lateral_offset + osc.y()) * left;
    p_C.z() = pc.height + osc.z();
    return body_pose_from_camera(look_at_R_CtoG(p_C, p_T), p_C, cam0);
  };

  ScenarioMotion m{BsplineSE3::from_function(robot_pose, 0.0, span, pc.spline_dt),
                   BsplineSE3::from_function(target_pose, 0.0, span, pc.spline_dt), 0.0, duration,
                   Eigen::AlignedBox2d()};
  m.workspace = bounds_of(m.robot, m.target, m.t_begin, span, config.map.margin);
  return m;
}

ScenarioMotion make_trajectory(const SimConfig& config) {
  const PoseTrajectory traj = load_tum_trajectory(config.trajectory.file);
  double dt = config.trajectory.spline_dt;
  if (dt <= 0.0) {
    dt = std::max((traj.poses.back().t - traj.poses.front().t) / static_cast<double>(traj.poses.size() - 1),
                  kMinFileSplineDt);
  }
  BsplineSE3 spline = BsplineSE3::fit(traj.poses, dt);
  double t_begin = spline.start_time();
  if (config.trajectory.start_distance > 0.0) {
    // Walk the path at 100 Hz until it is start_distance long.
    double travelled = 0.0;
    Eigen::Vector3d previous = spline.evaluate(t_begin).p_BinG;
    while (travelled < config.trajectory.start_distance) {
      t_begin += 0.01;
      if (t_begin >= spline.end_time()) {
        throw std::invalid_argument("trajectory scenario: the path of '" + traj.path + "' is shorter than " +
                                    "trajectory.start_distance " + fmt(config.trajectory.start_distance) + " m");
      }
      const Eigen::Vector3d p = spline.evaluate(t_begin).p_BinG;
      travelled += (p - previous).norm();
      previous = p;
    }
  }
  const double available = spline.end_time() - t_begin;
  if (config.duration > available) {
    throw std::invalid_argument("trajectory scenario: duration " + fmt(config.duration) + " s exceeds the " +
                                fmt(available) + " s the spline of '" + traj.path + "' covers");
  }
  const double duration = config.duration > 0.0 ? config.duration : available;
  ScenarioMotion m{std::move(spline), std::nullopt, 0.0, duration, Eigen::AlignedBox2d()};
  m.t_begin = t_begin;
  m.workspace = bounds_of(m.robot, m.target, m.t_begin, available, config.map.margin);
  return m;
}

ScenarioMotion make_mono(const SimConfig& config) {
  const MonoScenarioConfig& mc = config.mono;
  const CameraCalibration& cam0 = config.camera.calibrations.at(0);
  const double duration = config.duration > 0.0 ? config.duration : mc.duration;
  const double span = std::max(duration, mc.duration);
  const double h_T = target_center_height(config.target);

  auto heading_along_velocity = [&mc](double t) {
    const Eigen::Array2d w = kTwoPi * mc.object_frequency_hz.array();
    const Eigen::Vector2d v = mc.object_amplitude.array() * w * (w * t + mc.object_phase.array()).cos();
    // A motionless object (zero amplitudes) keeps yaw 0.
    return v.norm() > 1e-12 ? std::atan2(v.y(), v.x()) : 0.0;
  };
  const double yaw0 = heading_along_velocity(0.0);
  auto object_pose = [&mc, h_T, &heading_along_velocity, yaw0](double t) {
    const Eigen::Array2d arg = kTwoPi * mc.object_frequency_hz.array() * t + mc.object_phase.array();
    const Eigen::Vector2d p = mc.object_center.array() + mc.object_amplitude.array() * arg.sin();
    const double yaw = mc.object_heading == ObjectHeading::kFixed ? yaw0 : heading_along_velocity(t);
    return make_se3(rot_z(yaw), Eigen::Vector3d(p.x(), p.y(), h_T));
  };
  // Camera position relative to its anchor (G axes, or T axes for kObjectPose).
  auto relative_position = [&mc](double t) {
    return Eigen::Vector3d(mc.camera_base + mc.camera_velocity * t + eval_sinusoids(mc.camera_translation, t));
  };
  const Eigen::Matrix4d T_O0 = object_pose(0.0);
  const Eigen::Vector3d p_rel0 = relative_position(0.0);

  auto camera_pose = [&](double t, Eigen::Matrix3d* R_CtoG, Eigen::Vector3d* p_CinG) {
    const Eigen::Matrix4d T_O = object_pose(t);
    const Eigen::Matrix3d R_OtoG = T_O.topLeftCorner<3, 3>();
    const Eigen::Vector3d p_O = T_O.topRightCorner<3, 1>();
    const Eigen::Vector3d rel = relative_position(t);
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    switch (mc.anchor) {
      case CameraAnchor::kWorld:
      case CameraAnchor::kObjectTranslation: {
        *p_CinG = mc.anchor == CameraAnchor::kWorld ? rel : Eigen::Vector3d(p_O + rel);
        if (mc.pointing == CameraPointing::kLookAtObject) {
          R = look_at_R_CtoG(*p_CinG, p_O);
        } else {
          const Eigen::Vector3d p_C0 =
              mc.anchor == CameraAnchor::kWorld ? p_rel0 : Eigen::Vector3d(T_O0.topRightCorner<3, 1>() + p_rel0);
          R = look_at_R_CtoG(p_C0, T_O0.topRightCorner<3, 1>());
        }
        break;
      }
      case CameraAnchor::kObjectPose: {
        // Position and pointing defined in T (whose z is world z: planar object).
        *p_CinG = p_O + R_OtoG * rel;
        const Eigen::Vector3d p_CinT = mc.pointing == CameraPointing::kLookAtObject ? rel : p_rel0;
        R = R_OtoG * look_at_R_CtoG(p_CinT, Eigen::Vector3d::Zero());
        break;
      }
    }
    *R_CtoG = R * exp_so3(eval_sinusoids(mc.camera_wobble, t));
  };
  auto robot_pose = [&](double t) {
    Eigen::Matrix3d R_CtoG;
    Eigen::Vector3d p_CinG;
    camera_pose(t, &R_CtoG, &p_CinG);
    return body_pose_from_camera(R_CtoG, p_CinG, cam0);
  };

  ScenarioMotion m{BsplineSE3::from_function(robot_pose, 0.0, span, mc.spline_dt),
                   BsplineSE3::from_function(object_pose, 0.0, span, mc.spline_dt), 0.0, duration,
                   Eigen::AlignedBox2d(mc.room_min, mc.room_max)};
  return m;
}

}  // namespace

ScenarioMotion make_scenario(const SimConfig& config) {
  ScenarioMotion m = [&config]() {
    switch (config.scenario) {
      case Scenario::kPaper:
        return make_paper(config);
      case Scenario::kTrajectory:
        return make_trajectory(config);
      case Scenario::kMono:
        return make_mono(config);
    }
    throw std::invalid_argument("make_scenario: unknown scenario");
  }();
  if (!config.target.enabled) m.target.reset();
  return m;
}

Eigen::Matrix3d look_at_R_CtoG(const Eigen::Vector3d& p_CinG, const Eigen::Vector3d& p_lookG) {
  const Eigen::Vector3d d = p_lookG - p_CinG;
  if (!(d.norm() > 1e-9)) {
    throw std::invalid_argument("look_at_R_CtoG: camera and look-at point coincide");
  }
  const Eigen::Vector3d z_C = d.normalized();
  const Eigen::Vector3d x_raw = z_C.cross(Eigen::Vector3d::UnitZ());
  if (x_raw.norm() < 1e-6) {
    throw std::invalid_argument("look_at_R_CtoG: looking straight up or down, the horizontal x axis is undefined");
  }
  const Eigen::Vector3d x_C = x_raw.normalized();
  Eigen::Matrix3d R_CtoG;
  R_CtoG.col(0) = x_C;
  R_CtoG.col(1) = z_C.cross(x_C);
  R_CtoG.col(2) = z_C;
  return R_CtoG;
}

Eigen::Matrix4d body_pose_from_camera(const Eigen::Matrix3d& R_CtoG, const Eigen::Vector3d& p_CinG,
                                      const CameraCalibration& cam) {
  // p_C = R_ItoC p_I + p_IinC: the camera centre in I is -R_ItoC^T p_IinC.
  const Eigen::Matrix3d R_ItoG = R_CtoG * cam.R_ItoC;
  const Eigen::Vector3d p_CinI = -cam.R_ItoC.transpose() * cam.p_IinC;
  return make_se3(R_ItoG, p_CinG - R_ItoG * p_CinI);
}

Eigen::Vector3d eval_sinusoids(const std::vector<Sinusoid3>& terms, double t) {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (const Sinusoid3& s : terms) {
    out.array() += s.amplitude.array() * (kTwoPi * s.frequency_hz.array() * t + s.phase.array()).sin();
  }
  return out;
}

}  // namespace sim
}  // namespace vimot

#pragma once
// The paper scenario's `rc_car` target motion: a planar ground vehicle on a
// roughly semicircular course whose speed and turn rate vary as an RC car's
// do (RcCarConfig, docs/simulator.md).
//
// Geometry and timing are drawn separately, both from one seed:
//  * the path, as a function of arc length s: the semicircle's heading plus
//    a deviation, ψ(s) = ψ0 + s/radius + δ(s), δ drawn at n + 1 knots
//    spaced L/n ≈ heading_spacing over the length L = π radius, uniform in
//    ±heading_deviation, 0 at both ends (so the course turns by exactly π
//    and stays near the semicircle), joined by the quintic smoothstep
//    S(σ) = 10σ³ - 15σ⁴ + 6σ⁵; curvature 1/radius + δ'(s), S-bends where δ
//    swings; past L, δ = 0. Position ∫[cos ψ, sin ψ] ds by 3-point
//    Gauss-Legendre on a 5 cm grid (error < 1e-12 m);
//  * the distance driven s(t): legs of constant speed (a cruising speed in
//    [speed_min, speed_max] or a stop) joined by smoothstep speed changes
//    whose peak acceleration is max_acceleration (S' peaks at 15/8), s(t) in
//    closed form. The car stands at the start for t <= 0 and drives on past
//    L after duration(), so a spline sampled slightly outside [0, duration]
//    stays defined.
// The heading is the path tangent: the vehicle does not slip sideways.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "common/sim/sim_config.h"

namespace vimot {
namespace sim {

class RcCarCourse {
 public:
  /// Starts at (radius cos start_angle, radius sin start_angle, height)
  /// heading along +start_angle + π/2, as the semicircle does. Throws
  /// std::invalid_argument for a config that validate() refuses.
  RcCarCourse(const RcCarConfig& config, double radius, double start_angle, double height, uint64_t seed);

  double length() const { return length_; }      // m, π radius
  double duration() const { return duration_; }  // s to drive length()

  /// Distance along the path driven by time t (s); 0 for t <= 0.
  double distance(double t) const;
  /// Speed (m/s) at time t.
  double speed(double t) const;
  /// Heading (yaw of the body x axis, rad) at arc length s.
  double heading(double s) const;
  /// Body pose T_TtoG (yaw only, on the plane z = height) at time t.
  Eigen::Matrix4d pose(double t) const;

 private:
  struct SpeedSegment {
    double t0{0.0}, length_s{0.0};  // start time, duration (s)
    double v0{0.0}, v1{0.0};        // m/s at start and end (smoothstep between)
    double s0{0.0};                 // distance driven at t0 (m)
  };
  const SpeedSegment& segment_at(double t) const;
  double heading_deviation(double s) const;  // δ(s)
  Eigen::Vector2d position(double s) const;   // relative to the start
  Eigen::Vector2d tangent_integral(double a, double b) const;  // ∫_a^b [cos ψ, sin ψ] ds

  double length_{0.0};
  double duration_{0.0};
  double spacing_{0.0};
  double mean_curvature_{0.0};  // 1 / radius
  std::vector<double> knots_;   // δ at s = k spacing_
  double heading0_{0.0};
  Eigen::Vector3d start_{Eigen::Vector3d::Zero()};
  std::vector<SpeedSegment> segments_;
  std::vector<Eigen::Vector2d> grid_;  // position at s = k kGridStep
};

}  // namespace sim
}  // namespace vimot

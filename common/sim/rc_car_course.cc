#include "common/sim/rc_car_course.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include <Eigen/Geometry>

#include "common/sim/bspline_se3.h"

namespace vimot {
namespace sim {

namespace {

// Arc-length spacing (m) of the precomputed positions.
constexpr double kGridStep = 0.05;
// The car drives on this long after reaching the end of the course (s).
constexpr double kRunOut = 10.0;
// Peak of the smoothstep's slope, max S'(σ) = S'(1/2).
constexpr double kSmoothstepPeakSlope = 1.875;

// Quintic smoothstep S and its integral ∫_0^σ S.
double smoothstep(double x) { return x * x * x * (10.0 + x * (-15.0 + 6.0 * x)); }
double smoothstep_integral(double x) { return x * x * x * x * (2.5 + x * (-3.0 + x)); }

}  // namespace

RcCarCourse::RcCarCourse(const RcCarConfig& c, double radius, double start_angle, double height, uint64_t seed)
    : length_(M_PI * radius),
      spacing_(length_ / std::max(1.0, std::round(length_ / c.heading_spacing))),
      heading0_(start_angle + 0.5 * M_PI),
      start_(radius * std::cos(start_angle), radius * std::sin(start_angle), height) {
  if (!(radius > 0.0) || !(c.speed_min > 0.0) || !(c.speed_max >= c.speed_min) || !(c.max_acceleration > 0.0) ||
      !(c.hold_min > 0.0) || !(c.hold_max >= c.hold_min) || !(c.stop_min >= 0.0) || !(c.stop_max >= c.stop_min) ||
      !(c.stop_probability >= 0.0 && c.stop_probability < 1.0) || !(c.heading_spacing > 0.0)) {
    throw std::invalid_argument("RcCarCourse: invalid paper.rc_car config (see validate())");
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  auto draw = [&](double lo, double hi) { return lo + (hi - lo) * uniform(rng); };

  // Heading deviation knots over [0, L], zero at both ends.
  mean_curvature_ = 1.0 / radius;
  const auto n_intervals = static_cast<int>(std::lround(length_ / spacing_));
  knots_.assign(1, 0.0);
  for (int k = 1; k < n_intervals; ++k) knots_.push_back(draw(-c.heading_deviation, c.heading_deviation));
  knots_.push_back(0.0);

  // Speed legs until the course is driven, then kRunOut s more.
  double t = 0.0, s = 0.0, v = 0.0;
  auto add = [&](double duration, double v1) {
    SpeedSegment seg{t, duration, v, v1, s};
    segments_.push_back(seg);
    s += duration * (v + (v1 - v) * smoothstep_integral(1.0));
    t += duration;
    v = v1;
  };
  while (s < length_) {
    const bool stop = v > 0.0 && uniform(rng) < c.stop_probability;
    const double target = stop ? 0.0 : draw(c.speed_min, c.speed_max);
    const double hold = stop ? draw(c.stop_min, c.stop_max) : draw(c.hold_min, c.hold_max);
    const double change = std::abs(target - v);
    if (change > 0.0) add(kSmoothstepPeakSlope * change / c.max_acceleration, target);
    if (hold > 0.0) add(hold, target);
  }
  add(kRunOut, v);

  // First time the distance reaches L: bisection on the monotone s(t).
  double lo = 0.0, hi = t;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (distance(mid) < length_ ? lo : hi) = mid;
  }
  duration_ = hi;

  // Positions every kGridStep m up to the end of the run-out.
  const int n_grid = static_cast<int>(std::ceil(s / kGridStep)) + 2;
  grid_.assign(1, Eigen::Vector2d::Zero());
  for (int k = 0; k + 1 < n_grid; ++k) grid_.push_back(grid_.back() + tangent_integral(k * kGridStep, (k + 1) * kGridStep));
}

const RcCarCourse::SpeedSegment& RcCarCourse::segment_at(double t) const {
  // Last segment starting at or before t (t > 0 here).
  auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                             [](double time, const SpeedSegment& seg) { return time < seg.t0; });
  return *std::prev(it);
}

double RcCarCourse::distance(double t) const {
  if (t <= 0.0) return 0.0;
  const SpeedSegment& seg = segment_at(t);
  const double x = std::min((t - seg.t0) / seg.length_s, 1.0);
  const double end = seg.t0 + seg.length_s;
  const double beyond = t > end ? seg.v1 * (t - end) : 0.0;  // past the run-out: constant speed
  return seg.s0 + seg.length_s * (seg.v0 * x + (seg.v1 - seg.v0) * smoothstep_integral(x)) + beyond;
}

double RcCarCourse::speed(double t) const {
  if (t <= 0.0) return 0.0;
  const SpeedSegment& seg = segment_at(t);
  const double x = std::min((t - seg.t0) / seg.length_s, 1.0);
  return seg.v0 + (seg.v1 - seg.v0) * smoothstep(x);
}

double RcCarCourse::heading_deviation(double s) const {
  const auto k = static_cast<std::size_t>(std::floor(s / spacing_));
  if (k + 1 >= knots_.size()) return 0.0;  // past the course: the circle goes on
  return knots_[k] + (knots_[k + 1] - knots_[k]) * smoothstep(s / spacing_ - static_cast<double>(k));
}

double RcCarCourse::heading(double s) const {
  s = std::max(s, 0.0);
  return heading0_ + mean_curvature_ * s + heading_deviation(s);
}

Eigen::Vector2d RcCarCourse::position(double s) const {
  s = std::max(s, 0.0);
  const auto k = static_cast<std::size_t>(std::floor(s / kGridStep));
  if (k + 1 >= grid_.size()) throw std::out_of_range("RcCarCourse: distance beyond the course's run-out");
  return grid_[k] + tangent_integral(k * kGridStep, s);
}

Eigen::Vector2d RcCarCourse::tangent_integral(double a, double b) const {
  // 3-point Gauss-Legendre: exact to degree 5, error ~ (b - a)^7 per piece.
  static const double kNode[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)};
  static const double kWeight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  const double half = 0.5 * (b - a);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (int i = 0; i < 3; ++i) {
    const double psi = heading(a + half * (1.0 + kNode[i]));
    sum += kWeight[i] * Eigen::Vector2d(std::cos(psi), std::sin(psi));
  }
  return half * sum;
}

Eigen::Matrix4d RcCarCourse::pose(double t) const {
  const double s = distance(t);
  const Eigen::Vector2d xy = position(s);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(heading(s), Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return make_se3(R, start_ + Eigen::Vector3d(xy.x(), xy.y(), 0.0));
}

}  // namespace sim
}  // namespace vimot

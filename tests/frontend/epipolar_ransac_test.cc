// EpipolarRansac against two-view truth: points of a random 3D scene seen
// from two known poses (the epipolar constraint holds exactly), with pixel
// noise and injected outliers whose indices the test knows.
#include "common/frontend/epipolar_ransac.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

using namespace vimot::frontend;

namespace {

constexpr double kFocal = 450.0;  // px: converts pixel noise and thresholds to normalized units

struct TwoViews {
  std::vector<Eigen::Vector2d> a, b;
  std::vector<bool> outlier;
  Eigen::Matrix3d E{Eigen::Matrix3d::Zero()};  // the true essential matrix [t]x R
};

// Points 2-8 m in front of camera A; camera B rotated by `angle` about a
// tilted axis and displaced by `t` (p_B = R p_A + t). `noise_px` Gaussian
// pixel noise; a fraction `outliers` of the b points moved 5-40 px.
TwoViews make_views(int n, double angle, const Eigen::Vector3d& t, double noise_px, double outliers, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> xy(-1.5, 1.5), depth(2.0, 8.0), uni(0.0, 1.0), off(5.0, 40.0),
      dir(0.0, 2.0 * M_PI);
  std::normal_distribution<double> noise(0.0, noise_px / kFocal);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()).toRotationMatrix();
  TwoViews v;
  Eigen::Matrix3d tx;
  tx << 0.0, -t.z(), t.y(), t.z(), 0.0, -t.x(), -t.y(), t.x(), 0.0;
  v.E = tx * R;
  while (static_cast<int>(v.a.size()) < n) {
    const Eigen::Vector3d p(xy(rng), xy(rng), depth(rng));
    const Eigen::Vector3d q = R * p + t;
    if (q.z() < 0.5) continue;
    Eigen::Vector2d a = p.head<2>() / p.z(), b = q.head<2>() / q.z();
    if (std::abs(a.x()) > 0.8 || std::abs(a.y()) > 0.6 || std::abs(b.x()) > 0.8 || std::abs(b.y()) > 0.6) continue;
    a += Eigen::Vector2d(noise(rng), noise(rng));
    b += Eigen::Vector2d(noise(rng), noise(rng));
    const bool out = uni(rng) < outliers;
    if (out) {
      const double d = off(rng) / kFocal, th = dir(rng);
      b += d * Eigen::Vector2d(std::cos(th), std::sin(th));
    }
    v.a.push_back(a);
    v.b.push_back(b);
    v.outlier.push_back(out);
  }
  return v;
}

}  // namespace

TEST_CASE("eight_point_fundamental of exact correspondences satisfies the epipolar constraint") {
  const TwoViews v = make_views(50, 0.1, Eigen::Vector3d(0.3, -0.05, 0.1), 0.0, 0.0, 1);
  const Eigen::Matrix3d F = eight_point_fundamental(v.a, v.b);
  REQUIRE(F.norm() > 0.0);
  double max_sampson = 0.0;
  for (std::size_t i = 0; i < v.a.size(); ++i) {
    max_sampson = std::max(max_sampson, std::sqrt(sampson_distance_squared(F, v.a[i], v.b[i])));
  }
  CHECK(max_sampson * kFocal < 1e-6);
  // Rank 2, as every fundamental matrix.
  CHECK(std::abs(F.determinant()) < 1e-10 * F.norm() * F.norm() * F.norm());
}

TEST_CASE("sampson distance of a hand-derived case") {
  // Pure x translation: F = [t]x with t = (1, 0, 0) makes epipolar lines
  // horizontal; a point 0.01 off its line in b alone has Sampson distance
  // 0.01 / sqrt(2) (the error is shared between the two images).
  Eigen::Matrix3d F;
  F << 0, 0, 0, 0, 0, -1, 0, 1, 0;
  const double d2 = sampson_distance_squared(F, Eigen::Vector2d(0.2, 0.1), Eigen::Vector2d(0.5, 0.11));
  CHECK(std::sqrt(d2) == Approx(0.01 / std::sqrt(2.0)).epsilon(1e-9));
}

TEST_CASE("RANSAC rejects injected outliers and keeps the inliers") {
  RansacOptions o;
  o.threshold_px = 1.0;
  // 40 % outliers: an all-inlier 8-sample has probability 0.6^8 = 1.7 %,
  // so 99 % confidence needs ~270 samples; 1000 leaves room.
  o.max_iterations = 1000;
  EpipolarRansac ransac(o);
  struct Case {
    double angle;
    Eigen::Vector3d t;
    double outliers;
  };
  // Temporal-like small motion, stereo-like pure baseline, and a larger move.
  for (const Case& c :
       {Case{0.01, Eigen::Vector3d(0.05, 0.0, 0.02), 0.2}, Case{0.0, Eigen::Vector3d(-0.11, 0.0, 0.0), 0.3},
        Case{0.2, Eigen::Vector3d(0.4, 0.1, -0.2), 0.4}}) {
    const TwoViews v = make_views(200, c.angle, c.t, 0.3, c.outliers, 7);
    const std::vector<bool> in = ransac.inliers(v.a, v.b, kFocal);
    // An outlier moved along its epipolar line obeys the geometry and no
    // epipolar test can see it; every one moved > 2 px off the line (twice
    // the threshold, noise aside) must go.
    int outliers = 0, outliers_kept = 0, inliers = 0, inliers_kept = 0;
    for (std::size_t i = 0; i < in.size(); ++i) {
      if (v.outlier[i]) {
        if (std::sqrt(sampson_distance_squared(v.E, v.a[i], v.b[i])) * kFocal < 2.0) continue;
        ++outliers;
        outliers_kept += in[i] ? 1 : 0;
      } else {
        ++inliers;
        inliers_kept += in[i] ? 1 : 0;
      }
    }
    INFO("angle " << c.angle << ", outliers " << outliers << " (kept " << outliers_kept << "), inliers " << inliers
                  << " (kept " << inliers_kept << ")");
    CHECK(outliers > 20);
    CHECK(outliers_kept == 0);
    // 0.3 px noise against a 1 px threshold: nearly every inlier stays.
    CHECK(inliers_kept >= 0.95 * inliers);
  }
}

TEST_CASE("RANSAC keeps every match when there are too few to fit a model") {
  RansacOptions o;
  o.min_points = 10;
  EpipolarRansac ransac(o);
  const TwoViews v = make_views(9, 0.1, Eigen::Vector3d(0.2, 0.0, 0.0), 0.0, 0.5, 3);
  const std::vector<bool> in = ransac.inliers(v.a, v.b, kFocal);
  CHECK(std::count(in.begin(), in.end(), true) == 9);
  CHECK_THROWS_AS(ransac.inliers(v.a, std::vector<Eigen::Vector2d>(3), kFocal), std::invalid_argument);
}

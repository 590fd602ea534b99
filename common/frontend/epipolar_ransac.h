#pragma once
// Outlier rejection between two views: 8-point RANSAC on the fundamental
// matrix of undistorted (normalized) points, x_bᵀ F x_a = 0. On normalized
// points F is the essential matrix up to the rank-2 constraint, so one
// code path serves frame-to-frame and left-to-right matches of any lens.
// Inliers: Sampson distance below a threshold given in pixels and converted
// by the focal length. No LCM here.

#include <Eigen/Core>
#include <random>
#include <vector>

#include "common/frontend/tracker_options.h"

namespace vimot::frontend {

/// The least-squares 8-point fundamental matrix of >= 8 correspondences
/// (rank 2 enforced), or a zero matrix if the points are fewer.
Eigen::Matrix3d eight_point_fundamental(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b);

/// Squared Sampson distance of the correspondence a <-> b under F
/// (normalized units²); +inf where F maps a to no line.
double sampson_distance_squared(const Eigen::Matrix3d& F, const Eigen::Vector2d& a, const Eigen::Vector2d& b);

class EpipolarRansac {
 public:
  explicit EpipolarRansac(const RansacOptions& options);

  /// Inlier flags of the correspondences a[i] <-> b[i]. `focal_px` converts
  /// the pixel threshold to normalized units. With fewer than
  /// options.min_points correspondences no model is fitted and every one is
  /// kept (too few to tell outliers). Throws std::invalid_argument if the
  /// sizes differ.
  std::vector<bool> inliers(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                            double focal_px);

 private:
  RansacOptions options_;
  std::mt19937_64 rng_;
};

}  // namespace vimot::frontend

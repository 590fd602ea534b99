#pragma once
// Feature triangulation from the window poses (fixed extrinsics).
//
// All observations are expressed in the anchor camera A (camera and clone
// of the feature's first observation). Linear step: the point p minimising
// Σ ‖(I − b_i b_iᵀ)(p − p_CiinA)‖², b_i the unit bearing of observation i
// rotated into A. Refinement: Levenberg–Marquardt on the normalized
// reprojection error in anchored inverse depth x = [α β ρ] = [X/Z Y/Z 1/Z]:
//   h_i = R_AtoCi [α β 1]ᵀ + ρ p_AinCi,  ẑ_i = Π(h_i),
//   ∂ẑ_i/∂x = ∂Π(h_i) [R_AtoCi e1, R_AtoCi e2, p_AinCi].

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "common/estimator/feature_database.h"
#include "common/estimator/measurement_model.h"

namespace vimot {
namespace estimator {

struct TriangulationOptions {
  double min_depth{0.1};        // m, in the anchor camera
  double max_depth{60.0};       // m
  double max_condition{1e4};    // of the linear 3x3 system
  int max_iterations{10};       // Levenberg–Marquardt iterations
};

/// Pose estimate of one clone (R_GtoI, p_IinG).
struct ClonePose {
  Eigen::Matrix3d R_GtoI{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_IinG{Eigen::Vector3d::Zero()};
};
using ClonePoses = std::map<int64_t, ClonePose>;

class FeatureTriangulator {
 public:
  FeatureTriangulator(const TriangulationOptions& options, const std::vector<CameraInfo>& cameras);

  /// Sets feat.anchor_*, p_FinA and p_FinG. Observations must be at clone
  /// times in `clones` and of known cameras (others are ignored). Returns
  /// false if the geometry is degenerate, the point is behind a camera or
  /// outside [min_depth, max_depth].
  bool triangulate(Feature& feat, const ClonePoses& clones) const;

  const TriangulationOptions& options() const { return options_; }

 private:
  TriangulationOptions options_;
  std::vector<CameraInfo> cameras_;
};

}  // namespace estimator
}  // namespace vimot

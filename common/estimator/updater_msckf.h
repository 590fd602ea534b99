#pragma once
// MSCKF update (Mourikis & Roumeliotis 2007) with the features whose track
// ended or whose oldest observation leaves the window.
//
// Per feature f with observations z_ij (clone i, camera j):
//   1. triangulate p_FinG from the current clone estimates (triangulation.h);
//   2. r = z − Π(p̂_FinC), whitened by σ_j = σ_px / f_j;
//      H_x (w.r.t. the clone poses, FEJ values if use_fej), H_f (w.r.t. p_FinG);
//   3. left-nullspace projection: H_x ← Q2ᵀ H_x, r ← Q2ᵀ r (Givens, 2m − 3 rows);
//   4. chi² gate: rᵀ (H_x P_xx H_xᵀ + I)⁻¹ r < chi2_multiplier · χ²_0.95(2m − 3).
// The accepted systems are stacked, compressed by QR and applied in one EKF
// update on the clone block (StateHelper::ekf_update).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "common/estimator/feature_database.h"
#include "common/estimator/measurement_model.h"
#include "common/estimator/state.h"
#include "common/estimator/triangulation.h"
#include "common/estimator/updater_common.h"

namespace vimot {
namespace estimator {

struct MsckfOptions {
  double chi2_multiplier{1.0};     // gate at chi2_multiplier · χ²_0.95(dof)
  int max_features_per_update{40}; // longest tracks first
  int min_clone_times{2};          // distinct clone times a track needs
};

class UpdaterMsckf {
 public:
  UpdaterMsckf(const MsckfOptions& options, const TriangulationOptions& triangulation,
               const std::vector<CameraInfo>& cameras);

  /// Updates `state` with the given tracks (observations at times without
  /// a clone are dropped). Counts into *stats. Tracks beyond
  /// max_features_per_update (the shortest) are not tried: they are
  /// appended to *deferred if given, so the caller can keep them for a
  /// later update; every other track has been consumed (used or rejected).
  void update(State& state, std::vector<std::shared_ptr<Feature>> features, UpdateStats* stats,
              std::vector<std::shared_ptr<Feature>>* deferred = nullptr) const;

  /// The whitened linear system of one triangulated feature over `clones`
  /// (columns in layout order, which must hold every clone the feature is
  /// seen from): r = H_x x̃ + H_f p̃_FinG + n, n ~ N(0, I). False if a needed
  /// clone is missing or a camera id is unknown.
  bool feature_system(const State& state, const Feature& feat, ColumnLayout& layout, Eigen::MatrixXd* H_x,
                      Eigen::MatrixXd* H_f, Eigen::VectorXd* res) const;

  const MsckfOptions& options() const { return options_; }

 private:
  MsckfOptions options_;
  std::vector<CameraInfo> cameras_;
  FeatureTriangulator triangulator_;
};

/// Estimates (not FEJ) of every clone pose, for triangulation.
ClonePoses clone_poses(const State& state);

}  // namespace estimator
}  // namespace vimot

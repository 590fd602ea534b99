#pragma once
// SLAM features: landmarks kept in the state, updated with every new
// observation, initialised with delayed initialisation once a track spans
// the window, marginalised when their track ends. An anchored landmark
// moves to the newest clone before its anchor clone leaves the window.
//
// Representations (types.h LandmarkRepresentation):
//   kGlobalXyz: p_FinG. No anchor; the default.
//   kAnchoredInverseDepth: λ = [α β ρ] in a camera of the clone at the
//     initialisation time; p_FinG = f(λ, anchor pose) (measurement_model.h).
// Measurement z = Π(p_FinC) with the Jacobians of measurement_model.h,
// evaluated at FEJ values (clone, anchor, landmark) if use_fej.
//
// Update: per landmark, chi² gate with its marginal covariance
// (clone, landmark, anchor); a rejected observation is skipped, a landmark
// rejected max_chi2_failures frames in a row is flagged for marginalisation;
// the accepted rows form one EKF update.
// Delayed initialisation: triangulate, stack the whitened system
// r = H_R x̃_clones + H_L λ̃ + n and call StateHelper::initialize (QR split
// into the invertible part that defines the landmark and the rest that
// updates the state after its own chi² gate).

#include <Eigen/Core>
#include <map>
#include <memory>
#include <vector>

#include "common/estimator/feature_database.h"
#include "common/estimator/measurement_model.h"
#include "common/estimator/state.h"
#include "common/estimator/triangulation.h"
#include "common/estimator/updater_common.h"

namespace vimot {
namespace estimator {

struct SlamOptions {
  double chi2_multiplier{1.0};
  int max_init_per_frame{10};  // new SLAM features per camera frame at most
  int max_chi2_failures{2};    // consecutive rejected updates before marginalisation
};

/// Predicted measurement of a landmark from one clone and camera, and its
/// Jacobians (2×6 clone pose, 2×3 landmark, 2×6 anchor pose if anchored).
struct LandmarkMeasurement {
  Eigen::Vector2d z_hat{Eigen::Vector2d::Zero()};
  Eigen::Matrix<double, 2, 6> H_clone{Eigen::Matrix<double, 2, 6>::Zero()};
  Eigen::Matrix<double, 2, 3> H_landmark{Eigen::Matrix<double, 2, 3>::Zero()};
  Eigen::Matrix<double, 2, 6> H_anchor{Eigen::Matrix<double, 2, 6>::Zero()};
  std::shared_ptr<PoseJPL> anchor;  // nullptr for global landmarks
};

/// Evaluates the landmark measurement; false if the anchor clone is missing
/// or the point is behind the camera.
bool landmark_measurement(const State& state, const Landmark& landmark, const PoseJPL& clone, int camera_id,
                          const std::vector<CameraInfo>& cameras, LandmarkMeasurement* out);

class UpdaterSlam {
 public:
  UpdaterSlam(const SlamOptions& options, const TriangulationOptions& triangulation,
              const std::vector<CameraInfo>& cameras);

  /// EKF update with the observations at the newest clone time of landmarks
  /// in the state (`current` maps feature id → its observations now).
  void update(State& state, const std::map<int64_t, Feature>& current, UpdateStats* stats) const;

  /// Delayed initialisation of the given tracks (at most
  /// max_init_per_frame and the free SLAM slots); returns the feature ids
  /// that entered the state.
  std::vector<int64_t> delayed_initialize(State& state, std::vector<std::shared_ptr<Feature>> features,
                                          UpdateStats* stats) const;

  /// Anchor change before the clone at `marg_utime` leaves the window
  /// (OpenVINS's change_anchors): every anchored landmark anchored there and
  /// not flagged moves to the newest clone, same camera, with
  /// measurement_model.h change_anchor and StateHelper::transform_variable
  /// (Jacobian at the FEJ values if use_fej, as the measurement Jacobians).
  /// A landmark whose depth in the new anchor is not positive is flagged for
  /// marginalisation instead. Returns the number of landmarks re-anchored.
  int change_anchors(State& state, int64_t marg_utime) const;

  const SlamOptions& options() const { return options_; }

 private:
  SlamOptions options_;
  std::vector<CameraInfo> cameras_;
  FeatureTriangulator triangulator_;
};

}  // namespace estimator
}  // namespace vimot

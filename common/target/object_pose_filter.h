#pragma once
// World-frame motion filter of a rigid object observed through noisy metric
// poses (the monocular pipeline's OBJECT_POSE_METRIC, scale paper Eq. 21):
// smoothed pose, velocities, covariance and a prediction. Derivation and
// parameters: docs/object_motion_filter.md.
//
// State: the global target model of target_model.h with T = the object
// frame O, x = [q_GtoO, p_OinG, v_OinO, w_OinO] (TargetValue, R = G), error
// [δθ (in O), δp (G), δv, δw], plus the bias states below. Prediction:
// propagate_global (exact mean, Φ, Q_G of the constant-local-velocity model).
// Measurement: a pose z = (q_GtoO, p_OinG), residual r = z ⊟ x̂.pose()
// (boxminus of target_types.h: z = x̂ ⊞ r), H = [I₆ 0 H_b], covariance from the
// camera geometry (measurement_covariance()). One EKF update per pose,
// gated by χ²: rᵀ S⁻¹ r < chi2_multiplier · χ²_0.95(6).
//
// Slowly varying measurement errors are states, not white noise (a filter
// that averages them down is overconfident): b = [θ_b (3, rad, in O), p_b
// (3, m, in O), ε]. θ_b and p_b are the constant offsets of the tracker's O
// (orientation and origin, its initialisation errors, the same in every
// pose of a track); ε = ŝ/s − 1 is the relative error of the held scale ŝ
// used for the pose (s the true scale), so z_p = p + R_OtoG p_b + ε (p −
// p_CinG) exactly. A new held scale changes ε by the known ratio,
// ε ← (1 + ε) ŝ_new/ŝ_old − 1; in between ε is a random walk (the
// tracker's scale drift). Priors bias_sigma_theta, bias_sigma_position,
// scale_sigma; zeros give a 12-state filter.
//
// The first pose initialises the filter (v = w = 0 with σ init_sigma_v,
// init_sigma_w). A pose more than max_gap_s after the filter's time (the
// last pose, gated or not), or the max_consecutive_rejections-th gated pose
// in a row, re-initialises it: a constant-velocity extrapolation over a long
// gap, or a filter that rejects everything, would otherwise never recover.
// Non-finite input and a utime not after the filter's are refused and
// counted; nothing else changes.

#include <cstdint>

#include <Eigen/Core>

#include "common/target/target_model.h"
#include "common/target/target_types.h"

namespace vimot {
namespace target {

struct ObjectPoseFilterOptions {
  /// Random walk of v_OinO (m/s²/√Hz) and w_OinO (rad/s²/√Hz), per axis of O.
  /// Isotropic: the tracker's O has no relation to the object's own axes.
  TargetNoise noise{TargetNoise::isotropic(0.3, 1.0)};
  /// Position σ in the camera frame at distance d = |p_OinC|: k_lateral d on
  /// x, y (an angular error, rad) and k_depth d² along z (depth from a
  /// fixed-size object's image: σ_d ∝ d²).
  double k_lateral{0.003};  // rad
  double k_depth{0.004};    // 1/m
  /// Orientation σ per camera axis (rad), rotated into O.
  Eigen::Vector3d sigma_theta_C{Eigen::Vector3d::Constant(0.02)};
  /// Prior σ of the orientation offset θ_b per axis (rad) and of the
  /// held scale's relative error ε; random walk of ε (1/√s).
  double bias_sigma_theta{0.0};
  double bias_sigma_position{0.0};  // m, per axis of O
  double scale_sigma{0.0};
  double scale_random_walk{0.0};
  double init_sigma_v{0.5};  // m/s
  double init_sigma_w{0.5};  // rad/s
  double chi2_multiplier{1.0};
  int max_consecutive_rejections{5};
  double max_gap_s{1.0};  // s

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

/// One metric object pose with the camera geometry it came from.
struct ObjectPoseMeasurement {
  int64_t utime{0};
  Eigen::Vector4d q_GtoO{0.0, 0.0, 0.0, 1.0};  // JPL
  Eigen::Vector3d p_OinG{Eigen::Vector3d::Zero()};  // m
  Eigen::Vector3d p_OinC{Eigen::Vector3d::Zero()};  // m
  Eigen::Matrix3d R_CtoG{Eigen::Matrix3d::Identity()};
  /// The held scale ŝ the pose was computed with (> 0); its changes move ε.
  double scale{1.0};
};

/// Covariance of [δθ (O), δp (G)] of a measurement:
///   Σ_p = R_CtoG diag((k_lat d)², (k_lat d)², (k_depth d²)²) R_CtoGᵀ,
///   Σ_θ = R_CtoO diag(σ_θC²) R_CtoOᵀ,  R_CtoO = R_GtoO R_CtoG,
/// uncorrelated. (A rotation error φ_C of R_OtoC is δθ = R_CtoO φ_C.)
Matrix6d measurement_covariance(const ObjectPoseFilterOptions& options, const ObjectPoseMeasurement& z);

enum class ObjectFilterStatus {
  kInitialized,        // first pose (or after reset)
  kUpdated,
  kRejectedOutlier,    // χ² gate; the filter was predicted to the pose's utime
  kReinitialized,      // gap or too many consecutive outliers
  kRejectedTimeOrder,  // utime not after the filter's
  kRejectedInvalid,    // non-finite, zero quaternion or d = 0
};
const char* to_string(ObjectFilterStatus status);
/// The filter holds a state at the pose's utime.
inline bool is_accepted(ObjectFilterStatus s) {
  return s == ObjectFilterStatus::kInitialized || s == ObjectFilterStatus::kUpdated ||
         s == ObjectFilterStatus::kReinitialized;
}

struct ObjectPoseFilterStats {
  int64_t initializations{0};
  int64_t updates{0};
  int64_t outliers{0};
  int64_t reinitializations{0};      // after max_consecutive_rejections outliers in a row
  int64_t gap_reinitializations{0};  // after a gap above max_gap_s
  int64_t duplicates{0};
  int64_t backwards{0};
  int64_t invalid{0};
};

using Vector7d = Eigen::Matrix<double, 7, 1>;
using Matrix7d = Eigen::Matrix<double, 7, 7>;

class ObjectPoseFilter {
 public:
  /// Throws std::invalid_argument on invalid options.
  explicit ObjectPoseFilter(const ObjectPoseFilterOptions& options = ObjectPoseFilterOptions());

  ObjectFilterStatus add(const ObjectPoseMeasurement& z);

  bool initialized() const { return initialized_; }
  int64_t utime() const { return utime_; }
  /// Global target [q_GtoO, p_OinG, v_OinO, w_OinO] at utime() and its
  /// covariance (marginal: the biases' uncertainty is in it).
  const TargetValue& value() const { return x_; }
  Matrix12d covariance() const { return P_.topLeftCorner<12, 12>(); }
  /// Estimated measurement biases [θ_b (rad, O), p_b (m, O), ε] and their covariance.
  const Vector7d& biases() const { return b_; }
  Matrix7d bias_covariance() const { return P_.bottomRightCorner<7, 7>(); }
  /// Normalised innovation squared of the last gated pose (0 before any).
  double last_nis() const { return last_nis_; }
  /// The state horizon_s (>= 0) ahead with the motion model (predict_global).
  TargetPrediction predict(double horizon_s) const;

  /// Forgets the state and the time order (a new object frame); keeps stats.
  void reset();

  const ObjectPoseFilterStats& stats() const { return stats_; }
  const ObjectPoseFilterOptions& options() const { return options_; }

 private:
  using Matrix19d = Eigen::Matrix<double, 19, 19>;
  using Matrix6x7d = Eigen::Matrix<double, 6, 7>;
  void initialize(const ObjectPoseMeasurement& z, const Matrix6d& R);
  /// ∂z/∂b at a pose: I on θ_b, R_OtoG on p_b, p_OinG − p_CinG on ε.
  static Matrix6x7d bias_jacobian(const PoseValue& pose, const Eigen::Vector3d& p_CinG);

  ObjectPoseFilterOptions options_;
  bool initialized_{false};
  int64_t utime_{0};
  TargetValue x_;
  Vector7d b_{Vector7d::Zero()};
  Matrix19d P_{Matrix19d::Zero()};  // [δx (12); δb (7)]
  double held_scale_{1.0};
  int consecutive_rejections_{0};
  double last_nis_{0.0};
  ObjectPoseFilterStats stats_;
};

}  // namespace target
}  // namespace vimot

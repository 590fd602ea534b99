#pragma once
// Correlation-based metric scale estimator of a monocularly tracked object
// (Qiu et al., scale paper, Sections IV-B/C, Eq. 8-21). No LCM.
//
// Frames (paper notation -> vimot names, JPL quaternions of common/math/quat.h):
//   world w  = G, camera c = C, object o = O.
//   R_c^w = R_CtoG = quat_to_rot(q_GtoC)^T   (VINS, metric)
//   p_c^w = p_CinG                           (VINS, metric, m)
//   R_o^c = R_OtoC = quat_to_rot(q_OtoC)     (object tracker)
//   p̄_o^c = pbar_OinC                        (object tracker, up to scale)
//   p_o^c = s * pbar_OinC                     (metric, s the unknown scale)
//
// Motions (Eq. 8), n the derivative order, evaluated at interior window
// samples by non-uniform central finite differences:
//   m_c = d^n/dt^n p_CinG(t),   m_d = d^n/dt^n [R_CtoG(t) pbar_OinC(t)]
// (the rotated up-to-scale offset p_d^w of Eq. 5 is differentiated, not
// the rotation of a differentiated pbar_OinC).
// Closed form (Eq. 14) with D = Cov(m_d, m_c), C = Cov(m_c, m_c) (Eq. 12):
//   s* = -sum_ij D_ij C_ij / sum_ij D_ij^2,  f(s*) = sum_ij (s* D_ij + C_ij)^2
// Observability (Eq. 19): (i) f(s*) <= eps_t1, (ii) sum C_ij^2 >= rho_t1,
// (iii) sum D_ij^2 >= rho_t2; plus (4, vimot) s* > 0.
// See docs/scale_estimator.md for the derivations and the options.

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/config/config.h"

namespace vimot::scale {

struct ScaleEstimatorOptions {
  /// N_o: pose observations kept in the sliding window (paper: 200).
  int window_size{200};
  /// Estimate only with at least this many observations in the window
  /// (>= 4: the finite differences drop the two end samples and a sample
  /// covariance needs two motion samples). Default: a full window.
  int min_observations{200};
  /// n of Eq. 8: 1 = velocity (paper's choice), 2 = acceleration.
  int derivative_order{1};
  /// Band-pass of the motion samples, the same for m_c and m_d (not in the
  /// paper; 0 = off, the paper's estimator): m ← box_L(m) − box_H(m), box_w
  /// the centred moving average over w seconds. The high-pass removes the
  /// slow motion band where a moving object covaries with the camera over
  /// a finite window (Eq. 15's bias), the low-pass the frame-rate noise.
  /// Eq. 8 stays exact: the filter is linear. Samples whose box_H (or
  /// box_L) window does not fit in the window are dropped. See
  /// docs/scale_estimator.md ("Band-pass").
  double motion_lowpass_s{0.0};
  double motion_highpass_s{0.0};
  /// (i) f(s*) <= epsilon_t1. Units for n = 1: (m/s)^4; n = 2: (m/s^2)^4.
  double epsilon_t1{1e-3};
  /// (ii) sum_ij Cov^2(m_c^i, m_c^j) >= rho_t1, same units as epsilon_t1.
  double rho_t1{1e-2};
  /// (iii) sum_ij Cov^2(m_d^i, m_c^j) >= rho_t2. Units for n = 1:
  /// (u/s)^2 (m/s)^2 with u the tracker's arbitrary length unit.
  double rho_t2{1e-3};
  /// If true, (i) compares f(s*) / sum_ij C_ij^2 (in [0, 1], unitless)
  /// with epsilon_t1 instead of f(s*) (not in the paper; see docs).
  bool relative_condition_i{false};
  /// Reject s* <= 0 (failed_condition 4). Not in the paper: s* < 0 means
  /// the up-to-scale motion is positively correlated with the camera's,
  /// which independent motions cannot produce, yet Eq. 19 may pass it.
  bool require_positive_scale{true};
  /// A gap between consecutive observations above this clears the window
  /// before the new observation is added (finite differences must not span
  /// a tracking gap). <= 0 disables.
  double max_gap_s{1.0};
  /// |‖q‖ - 1| above this rejects an observation; below it q is normalised.
  double quat_norm_tolerance{1e-3};

  /// Keys of `section` (every key optional, defaults as above; an unknown
  /// key in the section is an error): window_size, min_observations,
  /// derivative_order, motion_lowpass_s, motion_highpass_s, epsilon_t1,
  /// rho_t1, rho_t2, relative_condition_i,
  /// require_positive_scale, max_gap_s, quat_norm_tolerance.
  /// Throws ConfigError naming the offending key.
  static ScaleEstimatorOptions from_config(const Config& cfg,
                                           const std::string& section = "scale_estimator");

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

/// One synchronized camera-frame observation (same utime for both poses).
struct ScaleObservation {
  int64_t utime{0};
  Eigen::Vector4d q_GtoC{0.0, 0.0, 0.0, 1.0};        // VINS camera attitude (JPL)
  Eigen::Vector3d p_CinG{Eigen::Vector3d::Zero()};    // VINS camera position, m
  Eigen::Vector4d q_OtoC{0.0, 0.0, 0.0, 1.0};        // tracker object attitude (JPL)
  Eigen::Vector3d pbar_OinC{Eigen::Vector3d::Zero()}; // tracker object position, up to scale

  /// From rotation matrices (R_CtoG = paper's R_c^w, R_OtoC = R_o^c).
  static ScaleObservation from_rotations(int64_t utime, const Eigen::Matrix3d& R_CtoG,
                                         const Eigen::Vector3d& p_CinG,
                                         const Eigen::Matrix3d& R_OtoC,
                                         const Eigen::Vector3d& pbar_OinC);
  Eigen::Matrix3d R_CtoG() const;
  /// p_d^w of Eq. 5: R_CtoG * pbar_OinC.
  Eigen::Vector3d p_d_in_G() const;
};

enum class AddStatus {
  kAdded,
  kAddedAfterGap,           // added; the window was cleared first (gap > max_gap_s)
  kRejectedNonFinite,       // a NaN / inf field
  kRejectedBadQuaternion,   // a quaternion norm off 1 by more than the tolerance
  kRejectedDuplicateTime,   // utime equal to the last accepted utime
  kRejectedTimeBackwards,   // utime before the last accepted utime
};
const char* to_string(AddStatus status);
inline bool is_added(AddStatus s) { return s == AddStatus::kAdded || s == AddStatus::kAddedAfterGap; }

struct AddStats {
  int64_t added{0};
  int64_t gap_resets{0};
  int64_t rejected_non_finite{0};
  int64_t rejected_bad_quaternion{0};
  int64_t rejected_duplicate_time{0};
  int64_t rejected_time_backwards{0};
};

enum class ScaleStatus {
  kInsufficientData,  // fewer than min_observations; nothing computed
  kRejected,          // computed, a condition failed
  kAccepted,          // computed, all conditions hold
};
const char* to_string(ScaleStatus status);

struct ScaleResult {
  ScaleStatus status{ScaleStatus::kInsufficientData};
  int64_t utime{0};          // newest observation used
  /// s* of Eq. 14; NaN if sum D_ij^2 == 0 (s* undefined: every s fits).
  double scale{std::numeric_limits<double>::quiet_NaN()};
  bool accepted{false};
  double f_value{std::numeric_limits<double>::quiet_NaN()};  // f(s*) of Eq. 13
  /// f(s*) / sum C_ij^2 in [0, 1] (0 if sum C_ij^2 == 0): sin^2 of the angle
  /// between D and C seen as 9-vectors. Informational unless
  /// relative_condition_i.
  double f_relative{std::numeric_limits<double>::quiet_NaN()};
  /// Eq. 19 figures: [0] f(s*) (or f_relative if relative_condition_i),
  /// [1] sum_ij C_ij^2, [2] sum_ij D_ij^2.
  std::array<double, 3> condition{{std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN()}};
  std::array<bool, 3> condition_ok{{false, false, false}};
  bool scale_positive_ok{false};
  /// 0 none, 1..3 the first failed sub-condition of Eq. 19, 4 s* <= 0
  /// (only if require_positive_scale). 0 with kInsufficientData.
  int failed_condition{0};
  int num_observations{0};     // pose observations in the window
  int num_motion_samples{0};   // m_c / m_d samples used (num_observations - 2, fewer with the band-pass)
  Eigen::Matrix3d cov_dc{Eigen::Matrix3d::Zero()};  // D_ij = Cov(m_d^i, m_c^j)
  Eigen::Matrix3d cov_cc{Eigen::Matrix3d::Zero()};  // C_ij = Cov(m_c^i, m_c^j)
};

/// d^n/dt^n of a sampled 3-vector trajectory at the interior samples
/// 1..N-2 (non-uniform 3-point central differences, exact for quadratics).
/// `utimes` strictly increasing; returns N-2 vectors (empty if N < 3).
/// Throws std::invalid_argument on n not in {1, 2}, size mismatch or a
/// non-increasing utime.
std::vector<Eigen::Vector3d> central_difference(const std::vector<int64_t>& utimes,
                                                const std::vector<Eigen::Vector3d>& values,
                                                int n);

/// box_L(m) − box_H(m) (see ScaleEstimatorOptions::motion_*_s) at the
/// samples k whose centred windows [t_k ∓ w/2] lie within [t_0, t_end];
/// lowpass_s = 0 keeps m_k, highpass_s = 0 subtracts nothing. A box
/// average includes the samples with |t_j − t_k| <= w/2. Throws
/// std::invalid_argument on a size mismatch or a negative width.
std::vector<Eigen::Vector3d> band_pass(const std::vector<int64_t>& utimes, const std::vector<Eigen::Vector3d>& m,
                                       double lowpass_s, double highpass_s);

/// The core of Eq. 12-14 and 19 on given motion samples (equal sizes >= 2).
/// Fills everything except utime and num_observations (set to m_c.size()+2).
ScaleResult estimate_scale(const std::vector<Eigen::Vector3d>& m_c,
                           const std::vector<Eigen::Vector3d>& m_d,
                           const ScaleEstimatorOptions& options);

/// Metric object pose in the world (Eq. 20-21).
struct ObjectPoseInWorld {
  int64_t utime{0};
  double scale{0.0};
  Eigen::Vector3d p_OinC{Eigen::Vector3d::Zero()};  // Eq. 20, m
  Eigen::Matrix3d R_OtoG{Eigen::Matrix3d::Identity()};
  Eigen::Vector4d q_GtoO{0.0, 0.0, 0.0, 1.0};       // JPL, R_GtoO = R_OtoG^T
  Eigen::Vector3d p_OinG{Eigen::Vector3d::Zero()};  // Eq. 21, m
};
ObjectPoseInWorld object_pose_in_world(double scale, const ScaleObservation& obs);

class ScaleEstimator {
 public:
  /// Throws std::invalid_argument on invalid options.
  explicit ScaleEstimator(const ScaleEstimatorOptions& options = ScaleEstimatorOptions());

  /// Validates and appends one observation, dropping the oldest beyond
  /// window_size. A rejected observation changes nothing but the stats.
  AddStatus add(const ScaleObservation& obs);

  /// Estimates from the current window (Eq. 8-19). If accepted, the scale
  /// becomes the held scale; otherwise the held scale is kept.
  ScaleResult update();

  /// add() then update() if added; nullopt if the observation was rejected.
  std::optional<ScaleResult> add_and_update(const ScaleObservation& obs, AddStatus* status = nullptr);

  bool has_scale() const { return accepted_.has_value(); }
  /// The held (last accepted) scale; NaN if none yet.
  double scale() const;
  const std::optional<ScaleResult>& last_accepted() const { return accepted_; }
  const ScaleResult& last_result() const { return last_result_; }

  /// Eq. 20-21 with the held scale on the newest observation; nullopt if
  /// no scale was accepted yet or the window is empty.
  std::optional<ObjectPoseInWorld> latest_object_pose() const;
  /// Eq. 20-21 with the held scale on any (valid) observation.
  std::optional<ObjectPoseInWorld> object_pose(const ScaleObservation& obs) const;

  /// Empties the window, keeps the held scale and the time ordering.
  void clear_window();
  /// Forgets everything (window, held scale, last utime): a new object.
  void reset();

  const std::deque<ScaleObservation>& window() const { return window_; }
  const AddStats& stats() const { return stats_; }
  const ScaleEstimatorOptions& options() const { return options_; }

 private:
  ScaleEstimatorOptions options_;
  std::deque<ScaleObservation> window_;
  std::optional<int64_t> last_utime_;
  std::optional<ScaleResult> accepted_;
  ScaleResult last_result_;
  AddStats stats_;
};

}  // namespace vimot::scale

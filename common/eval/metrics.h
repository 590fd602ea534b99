#pragma once
// Accuracy and consistency of a navigation estimate against ground truth at
// the same utime: the metrics every vimot evaluator reports.
//
// Conventions (those of the estimator, docs/estimator.md):
//  * position error δp = p_true − p̂ (m, in G);
//  * orientation error δθ = −log(R_true R̂ᵀ) (rad, in I), the estimator's
//    left error R_GtoI = Exp(−δθ) R̂_GtoI (common/math/quat.h);
//  * NEES of a 3-vector e with covariance block P: eᵀ P⁻¹ e. For a
//    consistent filter its mean over many samples (and Monte-Carlo runs) is
//    3, the dimension (Bar-Shalom, Li, Kirubarajan, "Estimation with
//    Applications to Tracking and Navigation", 2001, Sec. 5.4);
//  * 3σ bounds: 3 √diag(P) per axis.
// No LCM here.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"

namespace vimot {
namespace eval {

/// Errors of one estimate against the truth at the same utime.
struct ErrorSample {
  int64_t utime{0};                                     // µs
  Eigen::Vector3d err_p{Eigen::Vector3d::Zero()};       // m, p_true − p̂, in G
  Eigen::Vector3d err_theta{Eigen::Vector3d::Zero()};   // rad, −log(R_true R̂ᵀ), in I
  Eigen::Vector3d sig3_p{Eigen::Vector3d::Zero()};      // m, 3√diag(P_pp)
  Eigen::Vector3d sig3_theta{Eigen::Vector3d::Zero()};  // rad, 3√diag(P_θθ)
  double nees_p{0.0};
  double nees_theta{0.0};
};

/// Orientation error δθ (rad) with R_true = Exp(−δθ) R̂, both JPL q_GtoI.
Eigen::Vector3d orientation_error(const Eigen::Vector4d& q_GtoI_true, const Eigen::Vector4d& q_GtoI_est);

/// NEES eᵀ P⁻¹ e of a 3-vector. Throws std::invalid_argument if P is not
/// symmetric positive definite (a covariance that cannot be inverted makes
/// the NEES meaningless, and silently returning a number would hide it).
double nees3(const Eigen::Vector3d& e, const Eigen::Matrix3d& P);

/// All of ErrorSample for one estimate. P_theta and P_p are the [δθ] and
/// [δp] 3×3 blocks of the estimator's error-state covariance.
ErrorSample compute_error(int64_t utime, const Eigen::Vector4d& q_GtoI_true, const Eigen::Vector3d& p_IinG_true,
                          const Eigen::Vector4d& q_GtoI_est, const Eigen::Vector3d& p_IinG_est,
                          const Eigen::Matrix3d& P_theta, const Eigen::Matrix3d& P_p);

/// compute_error of a published state against the truth (same utime is the
/// caller's business): the blocks are covariance [δθ] rows 0–2, [δp] 3–5.
ErrorSample error_of(const NavState& estimate, const GroundTruth& truth);

/// The true target pose in the IMU frame [q_ItoT, p_TinI] of a GroundTruth
/// with has_target.
struct TargetInImu {
  Eigen::Vector4d q_ItoT;
  Eigen::Vector3d p_TinI;
};
TargetInImu true_target_in_imu(const GroundTruth& truth);

/// Root-mean-square errors and average NEES of one trajectory.
struct ErrorSummary {
  double rmse_position_m{0.0};       // √(Σ|δp|² / n)
  double rmse_orientation_deg{0.0};  // √(Σ|δθ|² / n), in degrees
  double nees_position{0.0};         // Σ NEES_p / n
  double nees_orientation{0.0};      // Σ NEES_θ / n
  // The RMSE the filter's own covariance predicts, √(Σ tr P / n): a
  // consistent filter's RMSE is this over many runs, so it tells how far
  // the configuration (sensors, features, window) lets the errors go down.
  double predicted_rmse_position_m{0.0};       // √(Σ tr P_pp / n)
  double predicted_rmse_orientation_deg{0.0};  // √(Σ tr P_θθ / n), in degrees
  int64_t count{0};                            // n
};

/// Accumulates ErrorSamples of one run into an ErrorSummary.
class TrajectoryErrors {
 public:
  void add(const ErrorSample& sample);
  int64_t count() const { return count_; }
  /// Zeros when empty.
  ErrorSummary summary() const;

 private:
  double sum_sq_p_{0.0};
  double sum_sq_theta_{0.0};
  double sum_nees_p_{0.0};
  double sum_nees_theta_{0.0};
  double sum_trace_p_{0.0};
  double sum_trace_theta_{0.0};
  int64_t count_{0};
};

/// Mean and sample standard deviation (n − 1; 0 for n < 2) of a list.
struct MeanStd {
  double mean{0.0};
  double std{0.0};
};
MeanStd mean_std(const std::vector<double>& values);

/// Monte-Carlo aggregate over runs: each run's ErrorSummary weighs the same.
struct MonteCarloSummary {
  int runs{0};
  MeanStd rmse_position_m;
  MeanStd rmse_orientation_deg;
  MeanStd nees_position;
  MeanStd nees_orientation;
  MeanStd predicted_rmse_position_m;
  MeanStd predicted_rmse_orientation_deg;
  int64_t samples{0};  // over all runs
};
MonteCarloSummary aggregate(const std::vector<ErrorSummary>& runs);

/// Order statistics of per-frame times (ms).
struct TimingStats {
  double mean_ms{0.0};
  double median_ms{0.0};
  double p95_ms{0.0};  // nearest-rank 95th percentile
  double max_ms{0.0};
  int64_t count{0};
};
TimingStats timing_stats(std::vector<double> ms);

}  // namespace eval
}  // namespace vimot

#pragma once
// The one class that touches the covariance: propagation, (Schmidt-)EKF
// update on a subset of variables, cloning, marginalisation and the
// initialisation of new variables from measurements.
//
// Measurement Jacobians are given for the involved variables only
// (H_order lists them; H has sum(size) columns in that order), so an update
// costs O(N · n_involved · m) instead of dense O(N² · m) products with a
// full-width H (N state size, m rows).
//
// Error-state convention: x = x̂ ⊞ x̃ (see types.h); residual r = z − h(x̂) ≈ H x̃ + n.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "common/estimator/state.h"
#include "common/estimator/types.h"

namespace vimot {
namespace estimator {

class StateHelper {
 public:
  /// Covariance propagation of the evolving variables `order` (e.g. the IMU):
  ///   P_xx ← Φ P_xx Φᵀ + Q,  P_xy ← Φ P_xy  (y: every other variable).
  /// O(n_x² N): the rest of the covariance is untouched.
  static void propagate(State& state, const std::vector<TypePtr>& order, const Eigen::MatrixXd& Phi,
                        const Eigen::MatrixXd& Q);

  /// EKF update with H over the variables in H_order (see header note):
  ///   S = H P_HH Hᵀ + R,  L = P_{:,H} Hᵀ,  K = L S⁻¹,
  ///   x̂ ← x̂ ⊞ K r,       P ← P − L S⁻¹ Lᵀ.
  /// Returns false (state unchanged) if S is not positive definite or a
  /// variable is not in the state.
  static bool ekf_update(State& state, const std::vector<TypePtr>& H_order, const Eigen::MatrixXd& H,
                         const Eigen::VectorXd& res, const Eigen::MatrixXd& R);

  /// Schmidt-Kalman update: the variables in `nuisance` are "considered",
  /// not estimated. With the state split into active a and nuisance n,
  ///   L = P Hᵀ = [L_a; L_n],  S = H P Hᵀ + R  (H may involve both),
  ///   K_a = L_a S⁻¹,  K_n = 0,
  ///   x̂_a ← x̂_a ⊞ K_a r,   x̂_n unchanged,
  ///   P_aa ← P_aa − L_a S⁻¹ L_aᵀ,
  ///   P_an ← P_an − L_a S⁻¹ L_nᵀ   (P_na its transpose),
  ///   P_nn unchanged.
  /// This is the Joseph form (I−KH) P (I−KH)ᵀ + K R Kᵀ with K = [K_a; 0]
  /// and the optimal K_a, so the covariance stays consistent; it equals
  /// P − L S⁻¹ Lᵀ with the (n, n) block of L S⁻¹ Lᵀ set to zero.
  /// An empty `nuisance` gives ekf_update.
  static bool schmidt_update(State& state, const std::vector<TypePtr>& H_order, const Eigen::MatrixXd& H,
                             const Eigen::VectorXd& res, const Eigen::MatrixXd& R,
                             const std::vector<TypePtr>& nuisance);

  /// Marginal covariance of `vars` (blocks in that order).
  static Eigen::MatrixXd marginal_covariance(const State& state, const std::vector<TypePtr>& vars);

  /// Removes `var` (a top-level variable of the state) and its rows/columns.
  static void marginalize(State& state, const TypePtr& var);

  /// Adds a copy of `var` (in the state, possibly a part such as
  /// imu()->pose()) fully correlated with it: P_new,: = P_var,:.
  static TypePtr clone(State& state, const TypePtr& var);

  /// Adds `var` (not in the state) with covariance P_vv and cross-covariance
  /// P_vx (P_vv.rows() × current size; empty means uncorrelated).
  static void add_variable(State& state, const TypePtr& var, const Eigen::MatrixXd& P_vv,
                           const Eigen::MatrixXd& P_vx = Eigen::MatrixXd());

  /// Adds `new_var` from an invertible linear system r = H_R x̃_R + H_L x̃_new + n,
  /// n ~ N(0, R), H_L square:
  ///   x̂_new ← x̂_new ⊞ H_L⁻¹ r,
  ///   P_new,new = H_L⁻¹ (H_R P_RR H_Rᵀ + R) H_L⁻ᵀ,   P_new,: = −H_L⁻¹ H_R P_R,: .
  static void initialize_invertible(State& state, const TypePtr& new_var, const std::vector<TypePtr>& H_order,
                                    const Eigen::MatrixXd& H_R, const Eigen::MatrixXd& H_L,
                                    const Eigen::VectorXd& res, const Eigen::MatrixXd& R);

  /// Delayed initialisation of `new_var` from m >= size rows with isotropic
  /// noise σ² I: Givens QR of H_L splits the system into an invertible part
  /// (first size rows, → initialize_invertible) and the rest (H_R2, r2),
  /// which must pass the chi² test r2ᵀ (H_R2 P H_R2ᵀ + σ²I)⁻¹ r2 <
  /// chi2_multiplier · χ²_0.95(m − size) and then updates the state.
  /// Returns false (state unchanged) if the test fails or H_L is rank deficient.
  static bool initialize(State& state, const TypePtr& new_var, const std::vector<TypePtr>& H_order,
                         Eigen::MatrixXd H_R, Eigen::MatrixXd H_L, Eigen::VectorXd res, double noise_sigma,
                         double chi2_multiplier);

  /// Linear change of variables of `var` (e.g. a landmark's anchor change):
  /// its error becomes x̃_var' = J x̃_order (J: var.size() × total size of
  /// `order`, which contains var); every other error is unchanged. Hence
  /// P ← T P Tᵀ with T the identity but for var's rows, which are J:
  ///   P_var,: ← J P_order,: ,   P_var,var ← J P_order,order Jᵀ.
  /// O(N · size(order)). The caller sets var's new value and FEJ.
  static void transform_variable(State& state, const TypePtr& var, const std::vector<TypePtr>& order,
                                 const Eigen::MatrixXd& J);

  /// Clones the IMU pose at the state time as the newest window pose.
  static void augment_clone(State& state, int64_t utime);

  /// Marginalises the oldest clones while there are more than max_clones.
  static void marginalize_old_clones(State& state);

  /// Adds a SLAM landmark already placed in the covariance (by initialize*).
  static void register_slam_feature(State& state, const std::shared_ptr<Landmark>& landmark);

  /// Marginalises every SLAM landmark flagged should_marginalize.
  static int marginalize_flagged_slam(State& state);

  /// Lays out a fresh state (only its IMU) as a checkpoint's: `variables`
  /// (containing state.imu()) in that order, `cov` their covariance, and
  /// which of them are clones (by utime) and SLAM landmarks.
  static void restore_layout(State& state, const std::vector<TypePtr>& variables, const Eigen::MatrixXd& cov,
                             std::map<int64_t, std::shared_ptr<PoseJPL>> clones,
                             std::map<int64_t, std::shared_ptr<Landmark>> slam);

  /// Overwrites the IMU estimate (value and FEJ), its covariance block and
  /// zeroes its correlations; used by initialisation and reset.
  static void reset_imu(State& state, const ImuValue& value, const Eigen::Matrix<double, 15, 15>& P_imu);

 private:
  // (id, size) blocks of `vars` with their total size; false if one is absent.
  static bool blocks_of(const std::vector<TypePtr>& vars, std::vector<std::pair<int, int>>* blocks, int* total);
  static void apply_correction(State& state, const Eigen::VectorXd& dx);
};

}  // namespace estimator
}  // namespace vimot

#pragma once
// Hooks through which an extension (e.g. the target filter, common/target/
// target_filter.h) adds variables to the VioEstimator's State and estimates
// them jointly with the robot. Attach with VioEstimator::set_extension();
// without an extension the estimator runs exactly as before (same code
// path, bit-identical results).
//
// Per camera frame at time t the estimator calls, in this order:
//   1. propagate_jointly(): the IMU prediction over [t0, t] is computed
//      (Propagator::predict_interval: x_I(t0), x_I(t), Φ_II, Q_II); the
//      extension returns the variables it propagates with the IMU and the
//      joint Φ, Q over [imu; those variables] (rows/columns 0..14 must be
//      Φ_II, Q_II); StateHelper::propagate applies them, then the IMU mean
//      is set and finally commit_propagation() lets the extension set its
//      own means at t.
//   2. on_clone_added(t) right after the IMU clone at t is added.
//   3. the static-feature updates (MSCKF, SLAM) on the whole state: the
//      extension's variables are corrected through their correlations.
//   4. update(t, observations flagged is_target), before marginalisation,
//      so the clone about to leave the window is still there.
//   5. on_clone_marginalized(t_old) just before the IMU clone at t_old is
//      marginalised.
// On VioEstimator::reset() the extension gets reset(); it must drop its
// variables' bookkeeping (the State is rebuilt).

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "common/estimator/propagator.h"
#include "common/estimator/state.h"
#include "common/estimator/types.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace estimator {

class VioExtension {
 public:
  virtual ~VioExtension() = default;

  /// Joint transition over [t0, t1] (dt seconds). Returns false to propagate
  /// the IMU alone (e.g. nothing to propagate yet). Otherwise *order starts
  /// with state.imu() and *Phi, *Q are square of the total size of *order.
  virtual bool propagate_jointly(const State& state, const ImuValue& x0, const ImuValue& x1, const Matrix15d& Phi_II,
                                 const Matrix15d& Q_II, int64_t t0, int64_t t1, std::vector<TypePtr>* order,
                                 Eigen::MatrixXd* Phi, Eigen::MatrixXd* Q) = 0;
  /// After the joint covariance propagation: set the extension's means at t1.
  virtual void commit_propagation(State& state) = 0;
  virtual void on_clone_added(State& state, int64_t utime) = 0;
  virtual void on_clone_marginalized(State& state, int64_t utime) = 0;
  virtual void update(State& state, int64_t utime, const std::vector<FeatureObservation>& target_observations) = 0;
  virtual void reset() = 0;
};

}  // namespace estimator
}  // namespace vimot

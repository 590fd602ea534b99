#pragma once
// The navigation state an estimator publishes (VINS_STATE), built from a
// VioEstimator in one place, so the `vins` process and the offline
// evaluator report exactly the same numbers. No LCM here.

#include "common/estimator/vio_estimator.h"
#include "common/types/nav_state.h"

namespace vimot {
namespace estimator {

/// The estimator's current IMU state: utime = state time, q/p/v/biases,
/// the 15×15 IMU covariance [δθ δp δv δbg δba], clone and SLAM counts, and
/// (updated = true only) the MSCKF features of the last update.
NavState nav_state_of(const VioEstimator& estimator, bool updated);

}  // namespace estimator
}  // namespace vimot

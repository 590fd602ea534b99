#include "common/estimator/nav_state_of.h"

namespace vimot {
namespace estimator {

NavState nav_state_of(const VioEstimator& est, bool updated) {
  NavState s;
  const ImuValue x = est.imu_value();
  s.utime = est.state_utime();
  s.updated = updated;
  s.q_GtoI = x.q_GtoI;
  s.p_IinG = x.p_IinG;
  s.v_IinG = x.v_IinG;
  s.bias_gyro = x.bg;
  s.bias_accel = x.ba;
  s.covariance = est.imu_covariance();
  s.num_clones = static_cast<int>(est.state().clones().size());
  s.num_slam_features = static_cast<int>(est.state().slam_features().size());
  s.num_msckf_features = updated ? est.last_stats().msckf_used : 0;
  return s;
}

}  // namespace estimator
}  // namespace vimot

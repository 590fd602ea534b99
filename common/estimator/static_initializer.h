#pragma once
// Static initialisation from an IMU window at rest.
//
// Over the last window_s seconds: ā = mean specific force, ω̄ = mean rate,
// σ_a² = mean ‖a − ā‖². If σ_a > max_accel_std the platform is moving and
// the initialiser waits. At rest a_m = R_GtoI g (+ ba), so the z axis of G
// in I is ā/‖ā‖; yaw is unobservable and set to 0 by taking the G x axis
// as the IMU x axis projected on the horizontal plane:
//   z = ā/‖ā‖,  x = normalize(e_x − z zᵀe_x),  y = z × x,  R_GtoI = [x y z].
// Then bg = ω̄, ba = 0, v = 0, p = 0.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <string>

#include "common/estimator/types.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace estimator {

struct StaticInitOptions {
  double window_s{1.0};           // s of data at rest required
  double max_accel_std{0.1};      // m/s²: above this the platform is moving
  double gravity_magnitude{9.81}; // m/s²
  double max_gravity_error{1.0};  // m/s²: | ‖ā‖ − g | allowed
};

enum class StaticInitStatus { kNotEnoughData, kMoving, kBadGravity, kReady };
const char* to_string(StaticInitStatus status);

class StaticInitializer {
 public:
  explicit StaticInitializer(const StaticInitOptions& options);

  /// Buffers a sample (non-finite and non-increasing ones are ignored).
  void feed_imu(const ImuData& imu);

  /// Tries to initialise from the newest window; on kReady fills *value and
  /// *utime (the newest sample time). *accel_std gets the measured σ_a.
  StaticInitStatus try_initialize(ImuValue* value, int64_t* utime, double* accel_std = nullptr) const;

  void clear() { buffer_.clear(); }

 private:
  StaticInitOptions options_;
  std::deque<ImuData> buffer_;
};

}  // namespace estimator
}  // namespace vimot

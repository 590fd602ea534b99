#pragma once
// Plain sensor measurements shared by the simulator, the estimators and the
// LCM adapters (which convert vimot.imu_t / vimot.features_t to and from
// these). No LCM here.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace vimot {

/// One IMU sample: body rate and specific force, both in the IMU frame I.
struct ImuData {
  int64_t utime{0};                                   // µs
  Eigen::Vector3d w_IinI{Eigen::Vector3d::Zero()};    // rad/s
  Eigen::Vector3d a_IinI{Eigen::Vector3d::Zero()};    // m/s², specific force
};

/// One feature seen by one camera at one time.
struct FeatureObservation {
  int64_t feature_id{0};
  int camera_id{0};                                      // 0 left, 1 right
  Eigen::Vector2d pixel{Eigen::Vector2d::Zero()};        // distorted pixels
  Eigen::Vector2d normalized{Eigen::Vector2d::Zero()};   // undistorted x/z, y/z
  bool is_target{false};                                 // on the tracked target
};

/// Every observation of every camera at one (synchronised) capture time.
struct CameraFrame {
  int64_t utime{0};  // µs
  std::vector<FeatureObservation> observations;
};

}  // namespace vimot

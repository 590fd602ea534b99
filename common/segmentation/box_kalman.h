#pragma once
// Kalman filter of a target's bounding box in one camera (paper 004,
// Sec. VI-A: the box of the largest mask blob is smoothed, and bridged
// through frames where the mask fails). No LCM here. Model and equations:
// docs/mask_filter.md.
//
// State x = [cu, cv, w, h, cu', cv', w', h'] (px, px/s): the box centre
// (cu = x_min + w/2, as frontend::Box::center_u), its size, and their rates,
// each a constant-velocity process driven by white acceleration noise.
// Measurement: a detected box as [cu, cv, w, h] with noise R.
//
// Gating: a detection whose Mahalanobis distance d² = yᵀS⁻¹y to the
// prediction exceeds χ²_p(4) is not fused (counted as rejected; the filter
// coasts). After max_consecutive_rejections rejections in a row the filter
// is re-initialised at the last one: the object has really jumped (or the
// track was on a false blob), and coasting on would only lose it.
//
// Coasting and dropping: without a fused detection the state is only
// predicted, so its covariance grows. Once the last fused detection is more
// than max_coast_s old the track is dropped (invalid) until the next
// detection initialises it. Time is the caller's utime only.

#include <Eigen/Core>
#include <cstdint>

namespace vimot::segmentation {

struct BoxKalmanOptions {
  double center_sigma_px{2.0};  // px, measurement noise of the detected centre (each axis)
  double size_sigma_px{3.0};    // px, measurement noise of the detected width and height
  double center_accel_noise{300.0};  // px/s²/√Hz, white acceleration noise density of the centre
  double size_accel_noise{100.0};    // px/s²/√Hz, same for width and height
  double init_center_velocity_sigma{200.0};  // px/s, prior std of the centre rate at initialisation
  double init_size_velocity_sigma{100.0};    // px/s, prior std of the size rates at initialisation
  double gate_probability{0.999};            // χ² gate: detections beyond this quantile (4 dof) are rejected
  int max_consecutive_rejections{3};         // this many rejections in a row re-initialise at the last one
  double max_coast_s{1.0};                   // s, the track is dropped this long after its last fused detection
  /// Throws std::invalid_argument naming the first invalid option.
  void validate() const;
};

class BoxKalmanFilter {
 public:
  using Vector8d = Eigen::Matrix<double, 8, 1>;
  using Matrix8d = Eigen::Matrix<double, 8, 8>;

  /// What step() did with the frame.
  enum class Outcome { kNoTrack, kInitialised, kFused, kRejected, kReinitialised, kCoasted, kDropped };

  /// Validates the options (std::invalid_argument).
  explicit BoxKalmanFilter(const BoxKalmanOptions& options);

  /// One frame at `utime` (µs, strictly after the previous step's, else
  /// std::invalid_argument), with this frame's detected box [x_min, y_min,
  /// width, height] or nullptr for none. kDropped: the track timed out at
  /// this frame (and there was no detection to restart it).
  Outcome step(int64_t utime, const Eigen::Vector4d* box);

  bool valid() const { return valid_; }
  /// Mahalanobis d² of the last gated detection (0 before any).
  double last_mahalanobis2() const { return last_d2_; }
  /// The gate threshold χ²_p(4).
  double gate() const { return gate_; }
  /// Frames since the last fused (or initialising) detection.
  int frames_since_fused() const { return frames_since_fused_; }

  /// The filtered box [x_min, y_min, width, height] (px); width and height
  /// are clamped at 0 (a shrinking box coasting past zero). Valid only.
  Eigen::Vector4d box() const;
  /// Rate of the box centre [cu', cv'] (px/s).
  Eigen::Vector2d center_velocity() const { return x_.segment<2>(4); }
  /// Covariance of box() in its own order [x_min, y_min, width, height] (px²).
  Eigen::Matrix4d box_covariance() const;
  const Vector8d& state() const { return x_; }
  const Matrix8d& covariance() const { return P_; }

 private:
  void initialise(int64_t utime, const Eigen::Vector4d& box);
  void predict(double dt);

  BoxKalmanOptions options_;
  double gate_{0.0};
  bool valid_{false};
  Vector8d x_{Vector8d::Zero()};
  Matrix8d P_{Matrix8d::Zero()};
  int64_t last_utime_{0};
  bool has_time_{false};
  int64_t last_fused_utime_{0};
  int frames_since_fused_{0};
  int consecutive_rejections_{0};
  double last_d2_{0.0};
};

}  // namespace vimot::segmentation

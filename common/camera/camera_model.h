#pragma once
// Pinhole camera with radial-tangential (plumb-bob) or equidistant (fisheye,
// Kannala-Brandt) distortion, as EuRoC / Kalibr and OpenCV calibrate them,
// plus its extrinsics to the IMU.
//
// Frames: a camera's extrinsics are R_ItoC, p_IinC: p_C = R_ItoC p_I + p_IinC.
// "normalized" coordinates are undistorted (x/z, y/z); "pixel" coordinates
// are distorted image coordinates (u, v).

#include <Eigen/Core>
#include <string>
#include <vector>

namespace vimot {

class Config;

/// How `CameraCalibration::distortion` maps a normalized point (x, y) to a
/// distorted one. kRadialTangential (OpenCV plumb-bob): k1, k2, p1, p2.
/// kEquidistant (OpenCV fisheye, Kalibr "equidistant"): k1..k4, with
/// θ = atan(r), θd = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸), x_d = (θd / r) x.
enum class DistortionModel { kRadialTangential, kEquidistant };

struct CameraCalibration {
  int width{0};
  int height{0};
  Eigen::Vector4d intrinsics{Eigen::Vector4d::Zero()};  // fx, fy, cx, cy (pixels)
  DistortionModel distortion_model{DistortionModel::kRadialTangential};
  Eigen::Vector4d distortion{Eigen::Vector4d::Zero()};  // radtan k1, k2, p1, p2 | equidistant k1..k4
  Eigen::Matrix3d R_ItoC{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_IinC{Eigen::Vector3d::Zero()};
};

class CameraModel {
 public:
  explicit CameraModel(const CameraCalibration& calibration);

  const CameraCalibration& calibration() const { return calib_; }

  /// Normalized (undistorted) -> pixel (distorted).
  Eigen::Vector2d distort(const Eigen::Vector2d& normalized) const;

  /// d pixel / d normalized, analytic.
  Eigen::Matrix2d distort_jacobian(const Eigen::Vector2d& normalized) const;

  /// Pixel -> normalized, by Gauss-Newton on distort() (radtan) or Newton on
  /// the angle off the axis (equidistant); throws std::runtime_error if it
  /// does not converge (far outside the image) or, for a fisheye, the ray is
  /// 90 degrees or more off the axis (no point on z = 1).
  Eigen::Vector2d undistort(const Eigen::Vector2d& pixel) const;

  /// True if the pixel lies inside the image with `border` pixels margin.
  bool in_image(const Eigen::Vector2d& pixel, double border = 0.0) const;

  /// Mean focal length (pixels): converts pixel noise to normalized noise.
  double mean_focal() const { return 0.5 * (calib_.intrinsics(0) + calib_.intrinsics(1)); }

 private:
  Eigen::Vector2d undistort_equidistant(const Eigen::Vector2d& pixel) const;

  CameraCalibration calib_;
};

/// Reads one camera in the ASL/EuRoC sensor.yaml layout from a Config node:
/// T_BS {rows: 4, cols: 4, data} (camera-to-body, body = IMU), resolution
/// [w, h], intrinsics [fu, fv, cu, cv], distortion_model radial-tangential
/// (distortion_coefficients [k1, k2, p1, p2]) or equidistant ([k1, k2, k3,
/// k4]). Throws ConfigError naming the key.
CameraCalibration camera_from_config(const Config& node);

/// Loads cam0 (and cam1 if present) of an ASL/EuRoC dataset folder
/// (<dir>/cam0/sensor.yaml, ...). Throws ConfigError if cam0 is missing.
std::vector<CameraCalibration> load_euroc_cameras(const std::string& mav0_dir);

}  // namespace vimot

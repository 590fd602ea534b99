#pragma once
// Test images with known geometry for the feature tracker tests: a texture
// with corners at several scales (so FAST, KLT and ORB behave as on real
// scenes), a textured plane rendered through a calibrated camera (exact
// pixel correspondences between any two poses), and simple pinhole cameras.

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "common/camera/camera_model.h"

namespace vimot::test {

/// A size x size grey texture of random filled rectangles (4-60 px sides,
/// random grey levels) over a mid-grey ground, lightly blurred so KLT sees
/// gradients rather than single-pixel steps.
inline cv::Mat make_texture(int width, int height, unsigned seed, int rectangles) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> x(0, width - 1), y(0, height - 1), side(4, 60), grey(0, 255);
  cv::Mat t(height, width, CV_8UC1, cv::Scalar(128));
  for (int i = 0; i < rectangles; ++i) {
    cv::rectangle(t, cv::Rect(x(rng), y(rng), side(rng), side(rng)), cv::Scalar(grey(rng)), cv::FILLED);
  }
  cv::GaussianBlur(t, t, cv::Size(3, 3), 0.8);
  return t;
}

/// A pinhole camera without distortion, cam0 at the IMU.
inline CameraCalibration pinhole(int width, int height, double focal) {
  CameraCalibration c;
  c.width = width;
  c.height = height;
  c.intrinsics << focal, focal, 0.5 * (width - 1), 0.5 * (height - 1);
  return c;
}

/// The plane z = depth of the world frame W, textured with `texture`
/// (texel_m metres per texel, texture centre at x = y = 0).
struct TexturedPlane {
  cv::Mat texture;
  double texel_m{0.008};
  double depth{3.0};

  /// Where the ray of `pixel` from a camera at pose (R_WtoC, p_WinC: p_C =
  /// R_WtoC p_W + p_WinC) meets the plane, in W.
  Eigen::Vector3d hit(const CameraModel& cam, const Eigen::Matrix3d& R_WtoC, const Eigen::Vector3d& p_WinC,
                      const Eigen::Vector2d& pixel) const {
    const Eigen::Vector2d n = cam.undistort(pixel);
    const Eigen::Vector3d d = R_WtoC.transpose() * Eigen::Vector3d(n.x(), n.y(), 1.0);
    const Eigen::Vector3d c = -R_WtoC.transpose() * p_WinC;
    return c + (depth - c.z()) / d.z() * d;
  }

  /// The image the camera sees (bilinear texture lookup, every pixel's ray
  /// through the camera model, distortion included).
  cv::Mat render(const CameraModel& cam, const Eigen::Matrix3d& R_WtoC, const Eigen::Vector3d& p_WinC) const {
    const CameraCalibration& c = cam.calibration();
    cv::Mat map_x(c.height, c.width, CV_32FC1), map_y(c.height, c.width, CV_32FC1);
    for (int v = 0; v < c.height; ++v) {
      for (int u = 0; u < c.width; ++u) {
        const Eigen::Vector3d P = hit(cam, R_WtoC, p_WinC, Eigen::Vector2d(u, v));
        map_x.at<float>(v, u) = static_cast<float>(P.x() / texel_m + 0.5 * texture.cols);
        map_y.at<float>(v, u) = static_cast<float>(P.y() / texel_m + 0.5 * texture.rows);
      }
    }
    cv::Mat out;
    cv::remap(texture, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_REFLECT);
    return out;
  }

  /// The true pixel in camera B of the plane point seen at `pixel_a` by A.
  Eigen::Vector2d transfer(const CameraModel& cam_a, const Eigen::Matrix3d& R_a, const Eigen::Vector3d& p_a,
                           const Eigen::Vector2d& pixel_a, const CameraModel& cam_b, const Eigen::Matrix3d& R_b,
                           const Eigen::Vector3d& p_b) const {
    const Eigen::Vector3d P = hit(cam_a, R_a, p_a, pixel_a);
    const Eigen::Vector3d q = R_b * P + p_b;
    return cam_b.distort(q.head<2>() / q.z());
  }
};

}  // namespace vimot::test

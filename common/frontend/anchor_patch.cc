#include "common/frontend/anchor_patch.h"

#include <Eigen/Dense>
#include <cmath>

namespace vimot::frontend {

namespace {

// Bilinear sample; the caller has checked that (x, y) and (x + 1, y + 1)
// are inside the image.
inline float sample(const cv::Mat& image, float x, float y) {
  const int x0 = static_cast<int>(std::floor(x));
  const int y0 = static_cast<int>(std::floor(y));
  const float ax = x - static_cast<float>(x0);
  const float ay = y - static_cast<float>(y0);
  const uint8_t* r0 = image.ptr<uint8_t>(y0) + x0;
  const uint8_t* r1 = image.ptr<uint8_t>(y0 + 1) + x0;
  const float top = static_cast<float>(r0[0]) + ax * static_cast<float>(r0[1] - r0[0]);
  const float bottom = static_cast<float>(r1[0]) + ax * static_cast<float>(r1[1] - r1[0]);
  return top + ay * (bottom - top);
}

// True if every sample of the square [c - r, c + r]² warped by `affine`
// about `pixel` has its four bilinear neighbours in the image (an affine
// image of a square is the parallelogram of its corners).
bool inside(const cv::Mat& image, cv::Point2f pixel, const Eigen::Matrix2f& affine, float r) {
  for (const float sx : {-r, r}) {
    for (const float sy : {-r, r}) {
      const Eigen::Vector2f q = Eigen::Vector2f(pixel.x, pixel.y) + affine * Eigen::Vector2f(sx, sy);
      if (!(q.x() >= 0.0f && q.y() >= 0.0f && q.x() < static_cast<float>(image.cols - 1) &&
            q.y() < static_cast<float>(image.rows - 1))) {
        return false;
      }
    }
  }
  return true;
}

}  // namespace

std::optional<AnchorPatch> AnchorPatch::take(const cv::Mat& image, cv::Point2f center, int window) {
  AnchorPatch p;
  p.half_ = window / 2;
  const int h = p.half_;
  const int side = 2 * h + 1;
  // One pixel more on each side for the central-difference gradients.
  if (!inside(image, center, Eigen::Matrix2f::Identity(), static_cast<float>(h + 1))) return std::nullopt;
  const int wide = side + 2;
  std::vector<float> t(static_cast<std::size_t>(wide * wide));
  for (int j = 0; j < wide; ++j) {
    for (int i = 0; i < wide; ++i) {
      t[static_cast<std::size_t>(j * wide + i)] =
          sample(image, center.x + static_cast<float>(i - h - 1), center.y + static_cast<float>(j - h - 1));
    }
  }
  p.template_.resize(static_cast<std::size_t>(side * side));
  p.steepest_.resize(p.template_.size());
  double mean = 0.0;
  Eigen::Matrix<double, 6, 6> hessian = Eigen::Matrix<double, 6, 6>::Zero();
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      const auto at = [&](int di, int dj) { return t[static_cast<std::size_t>((j + 1 + dj) * wide + i + 1 + di)]; };
      const float gx = 0.5f * (at(1, 0) - at(-1, 0));
      const float gy = 0.5f * (at(0, 1) - at(0, -1));
      const auto ux = static_cast<float>(i - h);
      const auto uy = static_cast<float>(j - h);
      const std::size_t k = static_cast<std::size_t>(j * side + i);
      p.template_[k] = at(0, 0);
      mean += at(0, 0);
      Eigen::Matrix<float, 6, 1>& s = p.steepest_[k];
      s << gx, gy, gx * ux, gx * uy, gy * ux, gy * uy;
      hessian += (s * s.transpose()).cast<double>();
    }
  }
  mean /= static_cast<double>(p.template_.size());
  double norm2 = 0.0;
  for (float& v : p.template_) {
    v -= static_cast<float>(mean);
    norm2 += static_cast<double>(v) * v;
  }
  p.template_norm_ = static_cast<float>(std::sqrt(norm2));
  // An edge or a flat patch cannot fix six warp parameters: the smallest
  // eigenvalue (relative to the largest) says whether the patch is usable.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(hessian);
  const double largest = eig.eigenvalues()(5);
  if (!(largest > 0.0) || eig.eigenvalues()(0) < 1e-6 * largest || p.template_norm_ < 1.0f) return std::nullopt;
  p.hessian_inverse_ = hessian.inverse().cast<float>();
  return p;
}

std::optional<AnchorPatch::Alignment> AnchorPatch::align(const cv::Mat& image, cv::Point2f guess,
                                                         const Eigen::Matrix2f& affine, int max_iterations,
                                                         float epsilon) const {
  const int side = 2 * half_ + 1;
  const std::size_t n = template_.size();
  std::vector<float> warped(n);
  Eigen::Vector2f p(guess.x, guess.y);
  Eigen::Matrix2f a = affine;
  float zncc = 0.0f;
  for (int iteration = 0; iteration < max_iterations; ++iteration) {
    if (!inside(image, cv::Point2f(p.x(), p.y()), a, static_cast<float>(half_))) return std::nullopt;
    double sum = 0.0;
    for (int j = 0; j < side; ++j) {
      const auto uy = static_cast<float>(j - half_);
      // Row start and step of the warped grid: p + a (ux, uy).
      float x = p.x() + a(0, 0) * static_cast<float>(-half_) + a(0, 1) * uy;
      float y = p.y() + a(1, 0) * static_cast<float>(-half_) + a(1, 1) * uy;
      for (int i = 0; i < side; ++i, x += a(0, 0), y += a(1, 0)) {
        const float v = sample(image, x, y);
        warped[static_cast<std::size_t>(j * side + i)] = v;
        sum += v;
      }
    }
    const auto mean = static_cast<float>(sum / static_cast<double>(n));
    double norm2 = 0.0, cross = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      warped[k] -= mean;
      norm2 += static_cast<double>(warped[k]) * warped[k];
      cross += static_cast<double>(warped[k]) * template_[k];
    }
    if (norm2 < 1.0) return std::nullopt;  // flat image patch: nothing to align
    const double norm = std::sqrt(norm2);
    zncc = static_cast<float>(cross / (norm * template_norm_));
    // The image patch scaled to the template's contrast: gain and offset
    // between the anchor image and this one drop out.
    const auto gain = static_cast<float>(template_norm_ / norm);
    Eigen::Matrix<float, 6, 1> b = Eigen::Matrix<float, 6, 1>::Zero();
    for (std::size_t k = 0; k < n; ++k) b += steepest_[k] * (gain * warped[k] - template_[k]);
    const Eigen::Matrix<float, 6, 1> delta = hessian_inverse_ * b;
    // Inverse composition: W(u) <- W(W_delta^-1(u)), W_delta(u) = u + d + D u.
    Eigen::Matrix2f step;
    step << 1.0f + delta(2), delta(3), delta(4), 1.0f + delta(5);
    const Eigen::Matrix2f step_inverse = step.inverse();
    const Eigen::Vector2f moved = -(a * (step_inverse * delta.head<2>()));
    a = a * step_inverse;
    p += moved;
    if (!p.allFinite() || !a.allFinite()) return std::nullopt;
    // Converged when the patch's centre and its corners (the change of the
    // affine part, a · step being the previous one, times the half width)
    // moved less than epsilon.
    const float corner_motion = (a - a * step).cwiseAbs().maxCoeff() * static_cast<float>(half_);
    if (moved.norm() < epsilon && corner_motion < epsilon) {
      return Alignment{cv::Point2f(p.x(), p.y()), a, zncc};
    }
  }
  return std::nullopt;
}

}  // namespace vimot::frontend

// AnchorPatch (common/frontend/anchor_patch.h): affine alignment of a track's
// anchor patch against images whose geometry is known exactly. The images
// are an analytic intensity field (a sum of Gaussian blobs) sampled at the
// pixel centres, so a warped image is the same field through the known
// affine map, with no resampling of its own.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/core.hpp>
#include <random>
#include <vector>

#include "common/frontend/anchor_patch.h"

using vimot::frontend::AnchorPatch;

namespace {

struct Blob {
  double x, y, sigma, amplitude;
};

std::vector<Blob> make_blobs(unsigned seed, int count, double extent) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> pos(0.0, extent), sigma(1.5, 4.0), amplitude(-60.0, 60.0);
  std::vector<Blob> blobs;
  for (int i = 0; i < count; ++i) blobs.push_back({pos(rng), pos(rng), sigma(rng), amplitude(rng)});
  return blobs;
}

// Image of the field f(x) = 128 + Σ blobs, seen through x_image = B x + t,
// with a gain and offset: I(x_image) = gain · f(B⁻¹ (x_image − t)) + offset.
cv::Mat render(const std::vector<Blob>& blobs, const Eigen::Matrix2d& B, const Eigen::Vector2d& t, double gain,
               double offset, int size) {
  const Eigen::Matrix2d B_inv = B.inverse();
  cv::Mat image(size, size, CV_8UC1);
  for (int v = 0; v < size; ++v) {
    for (int u = 0; u < size; ++u) {
      const Eigen::Vector2d x = B_inv * (Eigen::Vector2d(u, v) - t);
      double f = 128.0;
      for (const Blob& b : blobs) {
        const double dx = x.x() - b.x, dy = x.y() - b.y;
        f += b.amplitude * std::exp(-(dx * dx + dy * dy) / (2.0 * b.sigma * b.sigma));
      }
      image.at<uint8_t>(v, u) = cv::saturate_cast<uint8_t>(gain * f + offset);
    }
  }
  return image;
}

Eigen::Matrix2d similarity(double scale, double angle) {
  return scale * Eigen::Rotation2Dd(angle).toRotationMatrix();
}

}  // namespace

TEST_CASE("AnchorPatch finds a patch warped by a known affine map, gain and offset", "[frontend][anchor]") {
  const std::vector<Blob> blobs = make_blobs(3, 120, 100.0);
  const Eigen::Vector2d anchor(50.0, 50.0);
  const cv::Mat first = render(blobs, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), 1.0, 0.0, 100);
  const auto patch = AnchorPatch::take(first, cv::Point2f(50.0f, 50.0f), 15);
  REQUIRE(patch);

  // Scaled by 1.15, rotated by 8°, sheared; brighter and with more contrast.
  Eigen::Matrix2d B = similarity(1.15, 8.0 * M_PI / 180.0);
  B(0, 1) += 0.05;
  const Eigen::Vector2d t(3.3, -2.6);
  const cv::Mat second = render(blobs, B, t, 1.2, 15.0, 100);
  const Eigen::Vector2d truth = B * anchor + t;
  // Started 1.5 px off and from the identity warp.
  const auto a = patch->align(second, cv::Point2f(static_cast<float>(truth.x() + 1.0), static_cast<float>(truth.y() - 1.1)),
                              Eigen::Matrix2f::Identity(), 30, 0.01f);
  REQUIRE(a);
  INFO("aligned at (" << a->pixel.x << ", " << a->pixel.y << "), truth (" << truth.x() << ", " << truth.y() << ")");
  CHECK(std::hypot(a->pixel.x - truth.x(), a->pixel.y - truth.y()) < 0.05);
  CHECK((a->affine.cast<double>() - B).cwiseAbs().maxCoeff() < 0.02);
  CHECK(a->zncc > 0.99f);
}

TEST_CASE("AnchorPatch: the error does not grow along a long track", "[frontend][anchor]") {
  // 80 frames of a camera approaching and turning: the patch grows to 1.8×
  // and rotates by 24°. Each frame starts from the previous alignment (as
  // the tracker does after its KLT step); frame-to-frame tracking would
  // add each step's error to the next.
  const std::vector<Blob> blobs = make_blobs(7, 150, 120.0);
  const Eigen::Vector2d anchor(60.0, 60.0);
  const cv::Mat first = render(blobs, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), 1.0, 0.0, 120);
  const auto patch = AnchorPatch::take(first, cv::Point2f(60.0f, 60.0f), 15);
  REQUIRE(patch);
  cv::Point2f pixel(60.0f, 60.0f);
  Eigen::Matrix2f affine = Eigen::Matrix2f::Identity();
  double worst = 0.0;
  for (int k = 1; k <= 80; ++k) {
    const Eigen::Matrix2d B = similarity(1.0 + 0.01 * k, 0.005 * k);
    const Eigen::Vector2d truth(60.0 + 0.2 * k, 60.0 - 0.15 * k);
    const Eigen::Vector2d t = truth - B * anchor;
    const cv::Mat image = render(blobs, B, t, 1.0 - 0.003 * k, 0.2 * k, 120);
    const auto a = patch->align(image, pixel, affine, 30, 0.01f);
    REQUIRE(a);
    worst = std::max(worst, std::hypot(a->pixel.x - truth.x(), a->pixel.y - truth.y()));
    pixel = a->pixel;
    affine = a->affine;
  }
  INFO("worst error over 80 frames " << worst << " px");
  CHECK(worst < 0.05);
}

TEST_CASE("AnchorPatch refuses flat patches and patches off the image", "[frontend][anchor]") {
  const cv::Mat flat(60, 60, CV_8UC1, cv::Scalar(90));
  CHECK_FALSE(AnchorPatch::take(flat, cv::Point2f(30.0f, 30.0f), 15));
  // A straight edge fixes only one direction: the affine warp is undetermined.
  cv::Mat edge = flat.clone();
  edge.colRange(30, 60).setTo(200);
  CHECK_FALSE(AnchorPatch::take(edge, cv::Point2f(30.0f, 30.0f), 15));

  const std::vector<Blob> blobs = make_blobs(5, 80, 60.0);
  const cv::Mat image = render(blobs, Eigen::Matrix2d::Identity(), Eigen::Vector2d::Zero(), 1.0, 0.0, 60);
  CHECK_FALSE(AnchorPatch::take(image, cv::Point2f(5.0f, 30.0f), 15));  // window + gradient leaves the image
  const auto patch = AnchorPatch::take(image, cv::Point2f(30.0f, 30.0f), 15);
  REQUIRE(patch);
  CHECK(patch->align(image, cv::Point2f(30.0f, 30.0f), Eigen::Matrix2f::Identity(), 10, 0.01f));
  CHECK_FALSE(patch->align(image, cv::Point2f(55.0f, 30.0f), Eigen::Matrix2f::Identity(), 10, 0.01f));
  CHECK_FALSE(patch->align(flat, cv::Point2f(30.0f, 30.0f), Eigen::Matrix2f::Identity(), 10, 0.01f));
}

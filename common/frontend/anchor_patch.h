#pragma once
// A static track's appearance in its anchor image (where it was born, or
// last re-anchored), so that each later position is found by aligning this
// patch to the current image rather than the previous frame's. Frame-to-frame
// KLT re-centres its template on its own last estimate each frame, so its
// error accumulates with the track's age (docs/feature_tracker.md, "From
// pixels"); aligned to a fixed anchor, the error no longer grows.
//
// The alignment is Lucas-Kanade in its inverse-compositional form (Baker &
// Matthews 2004) with an affine warp, p + A u for a template offset u, which
// follows the patch's change of scale, rotation and foreshortening as the
// camera moves; gain and offset between the images are normalised out (the
// residual is the zero-mean, equal-variance difference, as in ZNCC). The
// template's gradients and Gauss-Newton matrix are computed once, when the
// patch is taken. No LCM here.

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace vimot::frontend {

class AnchorPatch {
 public:
  /// The (window × window, odd) patch of the 8-bit grey `image` centred on
  /// `center` (sub-pixel, bilinear). nullopt when the patch (plus one pixel
  /// for the gradients) leaves the image or has too little texture to fix
  /// an affine warp.
  static std::optional<AnchorPatch> take(const cv::Mat& image, cv::Point2f center, int window);

  struct Alignment {
    cv::Point2f pixel;               // where the anchor point is in the image
    Eigen::Matrix2f affine;          // the patch's warp, anchor offsets to image offsets
    float zncc{0.0f};                // normalised cross-correlation of the aligned patch
  };
  /// Aligns the patch to `image`, starting from `guess` and `affine`. nullopt
  /// when the warped patch leaves the image, the image patch is flat, or the
  /// iteration does not converge within `max_iterations` (step > `epsilon`
  /// px).
  std::optional<Alignment> align(const cv::Mat& image, cv::Point2f guess, const Eigen::Matrix2f& affine,
                                 int max_iterations, float epsilon) const;

 private:
  AnchorPatch() = default;
  int half_{0};
  std::vector<float> template_;         // zero-mean intensities, row-major over the window
  float template_norm_{0.0f};           // sqrt(sum of template_²)
  std::vector<Eigen::Matrix<float, 6, 1>> steepest_;  // ∇T · ∂W/∂(dx, dy, a00, a01, a10, a11) per pixel
  Eigen::Matrix<float, 6, 6> hessian_inverse_;
};

}  // namespace vimot::frontend

#include "common/segmentation/morphology.h"

#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace vimot::segmentation {

namespace {
bool odd_positive(int k) { return k >= 1 && k % 2 == 1; }
}  // namespace

void MorphologyOptions::validate() const {
  if (!odd_positive(erode_kernel_px)) {
    throw std::invalid_argument("morphology.erode_kernel_px must be odd and >= 1, got " +
                                std::to_string(erode_kernel_px));
  }
  if (!odd_positive(dilate_kernel_px)) {
    throw std::invalid_argument("morphology.dilate_kernel_px must be odd and >= 1, got " +
                                std::to_string(dilate_kernel_px));
  }
}

cv::Mat open_mask(const cv::Mat& mask, const MorphologyOptions& options) {
  if (mask.empty() || mask.type() != CV_8UC1) {
    throw std::invalid_argument("open_mask: expected a non-empty 8-bit single-channel mask, got type " +
                                std::to_string(mask.type()) + " " + std::to_string(mask.cols) + "x" +
                                std::to_string(mask.rows));
  }
  cv::Mat out;
  cv::threshold(mask, out, 0, 255, cv::THRESH_BINARY);
  // Square kernels: separable, so the cost does not grow with their area.
  if (options.erode_kernel_px > 1) {
    cv::erode(out, out, cv::getStructuringElement(cv::MORPH_RECT, {options.erode_kernel_px, options.erode_kernel_px}));
  }
  if (options.dilate_kernel_px > 1) {
    cv::dilate(out, out,
               cv::getStructuringElement(cv::MORPH_RECT, {options.dilate_kernel_px, options.dilate_kernel_px}));
  }
  return out;
}

}  // namespace vimot::segmentation

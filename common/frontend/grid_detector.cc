#include "common/frontend/grid_detector.h"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

namespace vimot::frontend {

namespace {
// FAST tests a circle of radius 3 around each pixel.
constexpr int kFastRadius = 3;
}  // namespace

std::vector<cv::Point2f> detect_grid_fast(const cv::Mat& image, const std::vector<cv::Point2f>& existing,
                                          const std::optional<Box>& box, const StaticTrackOptions& o) {
  const int cells = o.grid_cols * o.grid_rows;
  const int quota = (o.num_features + cells - 1) / cells;
  const double cell_w = static_cast<double>(image.cols) / o.grid_cols;
  const double cell_h = static_cast<double>(image.rows) / o.grid_rows;
  auto cell_of = [&](const cv::Point2f& p) {
    const int cx = std::clamp(static_cast<int>(p.x / cell_w), 0, o.grid_cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y / cell_h), 0, o.grid_rows - 1);
    return cy * o.grid_cols + cx;
  };

  // Forbidden pixels: near a tracked point, and the target box with its margin.
  cv::Mat free_mask(image.size(), CV_8UC1, cv::Scalar(255));
  const int radius = static_cast<int>(std::lround(o.min_distance_px));
  std::vector<int> count(static_cast<std::size_t>(cells), 0);
  for (const cv::Point2f& p : existing) {
    ++count[static_cast<std::size_t>(cell_of(p))];
    if (radius > 0) cv::circle(free_mask, p, radius, cv::Scalar(0), cv::FILLED);
  }
  if (box) {
    const int m = o.box_margin_px();
    const cv::Rect r(static_cast<int>(std::floor(box->x_min)) - m, static_cast<int>(std::floor(box->y_min)) - m,
                     static_cast<int>(std::ceil(box->width)) + 2 + 2 * m,
                     static_cast<int>(std::ceil(box->height)) + 2 + 2 * m);
    cv::rectangle(free_mask, r & cv::Rect(0, 0, image.cols, image.rows), cv::Scalar(0), cv::FILLED);
  }

  std::vector<cv::Point2f> out;
  const int border = std::max(o.border_px, kFastRadius);
  for (int cy = 0; cy < o.grid_rows; ++cy) {
    for (int cx = 0; cx < o.grid_cols; ++cx) {
      const int need = quota - count[static_cast<std::size_t>(cy * o.grid_cols + cx)];
      if (need <= 0) continue;
      const int x0 = std::max(border, static_cast<int>(std::floor(cx * cell_w)));
      const int y0 = std::max(border, static_cast<int>(std::floor(cy * cell_h)));
      const int x1 = std::min(image.cols - border, static_cast<int>(std::floor((cx + 1) * cell_w)));
      const int y1 = std::min(image.rows - border, static_cast<int>(std::floor((cy + 1) * cell_h)));
      if (x1 <= x0 || y1 <= y0) continue;
      // The ROI reaches FAST's radius beyond the cell so corners on the cell
      // edge are tested like any other; only corners inside the cell count.
      const cv::Rect roi(x0 - kFastRadius, y0 - kFastRadius, x1 - x0 + 2 * kFastRadius, y1 - y0 + 2 * kFastRadius);
      std::vector<cv::KeyPoint> kps;
      cv::FAST(image(roi), kps, o.fast_threshold, /*nonmaxSuppression=*/true);
      std::sort(kps.begin(), kps.end(),
                [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
      int added = 0;
      for (const cv::KeyPoint& kp : kps) {
        if (added >= need) break;
        const cv::Point2f p(kp.pt.x + static_cast<float>(roi.x), kp.pt.y + static_cast<float>(roi.y));
        const int u = static_cast<int>(std::lround(p.x)), v = static_cast<int>(std::lround(p.y));
        if (u < x0 || u >= x1 || v < y0 || v >= y1) continue;
        if (free_mask.at<uint8_t>(v, u) == 0) continue;
        out.push_back(p);
        ++added;
        if (radius > 0) cv::circle(free_mask, p, radius, cv::Scalar(0), cv::FILLED);
      }
    }
  }
  return out;
}

}  // namespace vimot::frontend

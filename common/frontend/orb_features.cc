#include "common/frontend/orb_features.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace vimot::frontend {

int hamming_distance(const Descriptor& a, const Descriptor& b) {
  int d = 0;
  for (int k = 0; k < 4; ++k)
    d += __builtin_popcountll(a[static_cast<std::size_t>(k)] ^ b[static_cast<std::size_t>(k)]);
  return d;
}

OrbBoxDetector::OrbBoxDetector(const TargetTrackOptions& o)
    // With a grid every cell must find candidates, not only the cells of
    // the strongest corners: as many candidates as the cells could take.
    : orb_(cv::ORB::create(o.num_features * o.grid * o.grid, static_cast<float>(o.orb_scale_factor), o.orb_levels,
                           /*edgeThreshold=*/31, /*firstLevel=*/0, /*WTA_K=*/2, cv::ORB::HARRIS_SCORE,
                           /*patchSize=*/31, o.orb_fast_threshold)) {
  // ORB needs a 31-pixel patch (scaled by the pyramid) around a keypoint; the
  // detector looks at the box grown by that much so corners near the box
  // edge can still be described.
  patch_radius_ = static_cast<int>(std::ceil(31.0 * std::pow(o.orb_scale_factor, o.orb_levels - 1)));
}

std::vector<OrbFeature> OrbBoxDetector::detect(const cv::Mat& image, const Box& box, const cv::Mat& allowed) const {
  const cv::Rect image_rect(0, 0, image.cols, image.rows);
  const cv::Rect box_rect(static_cast<int>(std::floor(box.x_min)), static_cast<int>(std::floor(box.y_min)),
                          static_cast<int>(std::ceil(box.width)) + 1, static_cast<int>(std::ceil(box.height)) + 1);
  const cv::Rect inner = box_rect & image_rect;
  if (inner.area() <= 0) return {};
  const cv::Rect roi = cv::Rect(inner.x - patch_radius_, inner.y - patch_radius_, inner.width + 2 * patch_radius_,
                                inner.height + 2 * patch_radius_) &
                       image_rect;
  cv::Mat mask(roi.size(), CV_8UC1, cv::Scalar(0));
  const cv::Rect inner_in_roi(inner.x - roi.x, inner.y - roi.y, inner.width, inner.height);
  if (allowed.empty()) {
    mask(inner_in_roi).setTo(255);
  } else {
    allowed(inner).copyTo(mask(inner_in_roi));
  }
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  orb_->detectAndCompute(image(roi), mask, kps, desc);
  std::vector<OrbFeature> out;
  out.reserve(kps.size());
  for (std::size_t i = 0; i < kps.size(); ++i) {
    OrbFeature f;
    f.pixel = cv::Point2f(kps[i].pt.x + static_cast<float>(roi.x), kps[i].pt.y + static_cast<float>(roi.y));
    // The mask admits whole pixels; the box is the exact test.
    if (!box.contains(f.pixel.x, f.pixel.y)) continue;
    f.response = kps[i].response;
    std::memcpy(f.descriptor.data(), desc.ptr<uint8_t>(static_cast<int>(i)), sizeof(Descriptor));
    out.push_back(f);
  }
  std::stable_sort(out.begin(), out.end(),
                   [](const OrbFeature& a, const OrbFeature& b) { return a.response > b.response; });
  return out;
}

std::vector<std::pair<int, int>> match_descriptors(const std::vector<Descriptor>& a, const std::vector<Descriptor>& b,
                                                   int max_distance, double ratio,
                                                   const std::function<bool(int, int)>& allowed) {
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  constexpr int kNone = std::numeric_limits<int>::max();
  std::vector<int> best_of_a(static_cast<std::size_t>(na), -1), best_a_dist(static_cast<std::size_t>(na), kNone),
      second_a_dist(static_cast<std::size_t>(na), kNone);
  std::vector<int> best_of_b(static_cast<std::size_t>(nb), -1), best_b_dist(static_cast<std::size_t>(nb), kNone);
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < nb; ++j) {
      if (allowed && !allowed(i, j)) continue;
      const int d = hamming_distance(a[static_cast<std::size_t>(i)], b[static_cast<std::size_t>(j)]);
      const auto ui = static_cast<std::size_t>(i);
      if (d < best_a_dist[ui]) {
        second_a_dist[ui] = best_a_dist[ui];
        best_a_dist[ui] = d;
        best_of_a[ui] = j;
      } else if (d < second_a_dist[ui]) {
        second_a_dist[ui] = d;
      }
      const auto uj = static_cast<std::size_t>(j);
      if (d < best_b_dist[uj]) {
        best_b_dist[uj] = d;
        best_of_b[uj] = i;
      }
    }
  }
  std::vector<std::pair<int, int>> out;
  for (int i = 0; i < na; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const int j = best_of_a[ui];
    if (j < 0 || best_of_b[static_cast<std::size_t>(j)] != i) continue;
    if (best_a_dist[ui] > max_distance) continue;
    if (second_a_dist[ui] != kNone && !(best_a_dist[ui] < ratio * second_a_dist[ui])) continue;
    out.emplace_back(i, j);
  }
  return out;
}

}  // namespace vimot::frontend

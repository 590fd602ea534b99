#pragma once
// ORB features inside the target box and Hamming-distance matching of their
// descriptors (target features: the target moves against the scene, so
// KLT's small-motion assumption and the scene's epipolar geometry do not
// hold for it; descriptors re-find its points). No LCM here.

#include <array>
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <utility>
#include <vector>

#include "common/frontend/box.h"
#include "common/frontend/tracker_options.h"

namespace vimot::frontend {

/// A 256-bit ORB descriptor.
using Descriptor = std::array<uint64_t, 4>;

int hamming_distance(const Descriptor& a, const Descriptor& b);

struct OrbFeature {
  cv::Point2f pixel;
  float response{0.0f};  // Harris score
  Descriptor descriptor{};
};

class OrbBoxDetector {
 public:
  explicit OrbBoxDetector(const TargetTrackOptions& options);

  /// At most options.num_features · grid² ORB features of an 8-bit grey
  /// image whose keypoints lie inside `box` (clipped to the image),
  /// strongest first; descriptors may use pixels around the box. Empty if
  /// the box misses the image. `allowed` (8-bit of the image's size, if
  /// given): keypoints only where it is nonzero, so the candidates are not
  /// spent on corners the caller would drop.
  std::vector<OrbFeature> detect(const cv::Mat& image, const Box& box, const cv::Mat& allowed = cv::Mat()) const;

 private:
  cv::Ptr<cv::ORB> orb_;
  int patch_radius_{0};
};

/// Pairs (i, j) of a[i] and b[j] that are each other's nearest descriptor
/// among the pairs `allowed(i, j)` admits, at distance <= max_distance, and
/// clearly nearer than a's second-nearest (best < ratio * second).
std::vector<std::pair<int, int>> match_descriptors(const std::vector<Descriptor>& a, const std::vector<Descriptor>& b,
                                                   int max_distance, double ratio,
                                                   const std::function<bool(int, int)>& allowed);

}  // namespace vimot::frontend

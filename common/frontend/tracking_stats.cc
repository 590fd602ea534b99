#include "common/frontend/tracking_stats.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace vimot::frontend {

namespace {
Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}
}  // namespace

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  if (v.size() % 2 == 1) return v[mid];
  const double upper = v[mid];
  const double lower = *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid));
  return 0.5 * (lower + upper);
}

TrackingStats::TrackingStats(const std::vector<CameraCalibration>& cameras) : cameras_(cameras) {
  if (cameras_.empty() || cameras_.size() > 2) {
    throw std::invalid_argument("TrackingStats: needs 1 or 2 cameras, got " + std::to_string(cameras_.size()));
  }
  if (cameras_.size() == 2) {
    // p_C1 = R_ItoC1 p_I + p_IinC1 with p_I = R_ItoC0ᵀ (p_C0 - p_IinC0).
    const Eigen::Matrix3d R_C0toC1 = cameras_[1].R_ItoC * cameras_[0].R_ItoC.transpose();
    const Eigen::Vector3d p_C0inC1 = cameras_[1].p_IinC - R_C0toC1 * cameras_[0].p_IinC;
    E_ = skew(p_C0inC1) * R_C0toC1;
    focal1_ = 0.5 * (cameras_[1].intrinsics(0) + cameras_[1].intrinsics(1));
  }
}

double TrackingStats::epipolar_error_px(const Eigen::Vector2d& x0, const Eigen::Vector2d& x1) const {
  const Eigen::Vector3d line = E_ * Eigen::Vector3d(x0.x(), x0.y(), 1.0);
  const double norm = std::hypot(line.x(), line.y());
  return focal1_ * std::abs(line.dot(Eigen::Vector3d(x1.x(), x1.y(), 1.0))) / norm;
}

void TrackingStats::add(const CameraFrame& frame) {
  int n_static = 0;
  std::set<int64_t> seen;
  std::unordered_map<int64_t, Eigen::Vector2d> left;
  for (const FeatureObservation& o : frame.observations) {
    if (o.is_target) {
      target_observations_ += o.camera_id == 0 ? 1 : 0;
      continue;
    }
    seen.insert(o.feature_id);
    if (o.camera_id == 0) {
      ++n_static;
      left.emplace(o.feature_id, o.normalized);
    }
  }
  static_per_frame_.push_back(n_static);
  for (const int64_t id : seen) ++track_length_[id];
  if (cameras_.size() < 2) return;
  for (const FeatureObservation& o : frame.observations) {
    if (o.is_target || o.camera_id != 1) continue;
    const auto it = left.find(o.feature_id);
    if (it != left.end()) epipolar_px_.push_back(epipolar_error_px(it->second, o.normalized));
  }
}

TrackingFigures TrackingStats::figures() const {
  TrackingFigures f;
  f.frames = static_cast<int>(static_per_frame_.size());
  if (static_per_frame_.size() >= 2) {
    f.min_static_per_frame = *std::min_element(static_per_frame_.begin() + 1, static_per_frame_.end());
  }
  if (!static_per_frame_.empty()) {
    f.mean_static_per_frame = std::accumulate(static_per_frame_.begin(), static_per_frame_.end(), 0.0) /
                              static_cast<double>(static_per_frame_.size());
    f.mean_target_per_frame = static_cast<double>(target_observations_) / static_cast<double>(static_per_frame_.size());
  }
  std::vector<double> lengths;
  for (const auto& [id, n] : track_length_) lengths.push_back(n);
  f.median_track_length = median(lengths);
  f.median_epipolar_px = median(epipolar_px_);
  f.stereo_observations = epipolar_px_.size();
  return f;
}

}  // namespace vimot::frontend

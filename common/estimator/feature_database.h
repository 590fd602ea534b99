#pragma once
// Feature tracks of the static scene (normalized coordinates per camera and
// clone time), and the triangulation result the MSCKF/SLAM updaters attach.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "common/types/sensor_data.h"

namespace vimot {
namespace estimator {

struct FeatureObs {
  int64_t utime{0};                                // µs, a clone time
  Eigen::Vector2d uv{Eigen::Vector2d::Zero()};     // normalized (undistorted) coordinates
};

struct Feature {
  int64_t feature_id{0};
  std::map<int, std::vector<FeatureObs>> obs;      // by camera id, time-ordered

  // Triangulation output (anchor camera frame and global).
  int anchor_camera{0};
  int64_t anchor_utime{-1};
  Eigen::Vector3d p_FinA{Eigen::Vector3d::Zero()};
  Eigen::Vector3d p_FinG{Eigen::Vector3d::Zero()};

  int num_obs() const;
  int64_t first_utime() const;
  int64_t last_utime() const;
  /// Distinct observation times.
  std::set<int64_t> times() const;
  bool observed_at(int64_t utime) const;
  /// Drops observations whose time is not in `keep`; returns obs left.
  int keep_times(const std::set<int64_t>& keep);
};

class FeatureDatabase {
 public:
  /// Adds one observation at utime; repeated (feature, camera, utime) are ignored.
  void add(int64_t utime, int64_t feature_id, int camera_id, const Eigen::Vector2d& uv);

  /// Features whose last observation is before utime (tracks that ended).
  std::vector<std::shared_ptr<Feature>> lost_before(int64_t utime) const;
  /// Features with an observation at utime.
  std::vector<std::shared_ptr<Feature>> observed_at(int64_t utime) const;

  std::shared_ptr<Feature> get(int64_t feature_id) const;
  void remove(int64_t feature_id);
  /// Drops observations older than utime and features left empty.
  void clean_older_than(int64_t utime);
  void clear() { features_.clear(); }
  size_t size() const { return features_.size(); }
  /// Every track by feature id (a checkpoint's), and one put back as it was.
  const std::map<int64_t, std::shared_ptr<Feature>>& features() const { return features_; }
  void insert(const Feature& feature) { features_[feature.feature_id] = std::make_shared<Feature>(feature); }

 private:
  std::map<int64_t, std::shared_ptr<Feature>> features_;
};

}  // namespace estimator
}  // namespace vimot

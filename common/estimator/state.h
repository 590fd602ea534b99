#pragma once
// The estimator state: IMU, a sliding window of IMU pose clones keyed by
// utime, SLAM landmarks keyed by feature id, and the covariance of the
// stacked error state (variables in the order of variables()).
//
// Only StateHelper changes the covariance and the set of variables.

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "common/estimator/types.h"

namespace vimot {
namespace estimator {

struct StateOptions {
  int max_clones{11};       // sliding-window length (IMU pose clones)
  int max_slam{50};         // SLAM landmarks kept in the state at most
  bool use_fej{true};       // first-estimate Jacobians
  LandmarkRepresentation slam_representation{LandmarkRepresentation::kGlobalXyz};
};

class State {
 public:
  explicit State(const StateOptions& options);

  const StateOptions& options() const { return options_; }

  /// Time (µs) of the IMU state.
  int64_t utime() const { return utime_; }
  void set_utime(int64_t utime) { utime_ = utime; }

  const std::shared_ptr<ImuState>& imu() const { return imu_; }

  /// Pose clones, oldest first.
  const std::map<int64_t, std::shared_ptr<PoseJPL>>& clones() const { return clones_; }
  /// The clone at `utime`, or nullptr.
  std::shared_ptr<PoseJPL> clone_at(int64_t utime) const;
  /// Oldest clone time; -1 without clones.
  int64_t oldest_clone_utime() const { return clones_.empty() ? -1 : clones_.begin()->first; }

  /// SLAM landmarks by feature id. Updaters may flag should_marginalize;
  /// adding and removing goes through StateHelper.
  const std::map<int64_t, std::shared_ptr<Landmark>>& slam_features() const { return slam_; }

  const Eigen::MatrixXd& cov() const { return cov_; }
  int cov_size() const { return static_cast<int>(cov_.rows()); }
  const std::vector<TypePtr>& variables() const { return variables_; }

 private:
  friend class StateHelper;

  StateOptions options_;
  int64_t utime_{0};
  std::shared_ptr<ImuState> imu_;
  std::map<int64_t, std::shared_ptr<PoseJPL>> clones_;
  std::map<int64_t, std::shared_ptr<Landmark>> slam_;
  Eigen::MatrixXd cov_;
  std::vector<TypePtr> variables_;
};

}  // namespace estimator
}  // namespace vimot

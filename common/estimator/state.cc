#include "common/estimator/state.h"

#include <stdexcept>
#include <string>

namespace vimot {
namespace estimator {

State::State(const StateOptions& options) : options_(options), imu_(std::make_shared<ImuState>()) {
  if (options_.max_clones < 2) {
    throw std::invalid_argument("StateOptions: max_clones must be >= 2, got " + std::to_string(options_.max_clones));
  }
  if (options_.max_slam < 0) {
    throw std::invalid_argument("StateOptions: max_slam must be >= 0, got " + std::to_string(options_.max_slam));
  }
  imu_->set_local_id(0);
  variables_.push_back(imu_);
  cov_ = 1e-3 * Eigen::MatrixXd::Identity(imu_->size(), imu_->size());
}

std::shared_ptr<PoseJPL> State::clone_at(int64_t utime) const {
  const auto it = clones_.find(utime);
  return it == clones_.end() ? nullptr : it->second;
}

}  // namespace estimator
}  // namespace vimot

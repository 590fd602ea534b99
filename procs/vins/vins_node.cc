#include "procs/vins/vins_node.h"

#include <sstream>

#include "common/estimator/initial_estimate.h"
#include "common/estimator/nav_state_of.h"
#include "common/estimator/vins_config.h"

namespace vimot {

VinsNodeOptions vins_node_options_from_config(const Config& cfg) {
  cfg.check_keys("", estimator::vins_config_keys());
  cfg.check_keys("output", {"imu_rate"});
  VinsNodeOptions options;
  options.vio = estimator::vio_options_from_config(cfg);
  const estimator::VinsStartOptions start = estimator::start_options_from_config(cfg);
  options.init_from_ground_truth = start.mode == estimator::InitMode::kGroundTruth;
  options.perturb_seed = start.perturb_seed;
  options.publish_imu_rate = cfg.get_or<bool>("output.imu_rate", options.publish_imu_rate);
  return options;
}

VinsNode::VinsNode(const VinsNodeOptions& options, StateCallback on_state, EventCallback on_event)
    : options_(options), estimator_(options.vio), on_state_(std::move(on_state)), on_event_(std::move(on_event)) {}

void VinsNode::set_frame_hooks(std::function<void(const CameraFrame&)> before_frame,
                               std::function<void()> after_update) {
  before_frame_ = std::move(before_frame);
  after_update_ = std::move(after_update);
}

void VinsNode::say(NodeEvent::Kind kind, const std::string& message) {
  if (on_event_) on_event_(NodeEvent{kind, message});
}

void VinsNode::on_imu(const ImuData& imu) {
  const estimator::ImuFeedStatus status = estimator_.feed_imu(imu);
  switch (status) {
    case estimator::ImuFeedStatus::kAccepted:
      break;
    case estimator::ImuFeedStatus::kAcceptedAfterGap:
      say(NodeEvent::Kind::kInfo, "IMU gap before utime " + std::to_string(imu.utime) + " (propagating across it)");
      break;
    default:
      say(NodeEvent::Kind::kDropped,
          std::string("IMU sample at utime ") + std::to_string(imu.utime) + ": " + estimator::to_string(status));
      return;
  }
  process_ready_frames(imu.utime);
  if (options_.publish_imu_rate && queued_frames_.empty()) publish_propagated(imu.utime);
}

void VinsNode::on_frame(const CameraFrame& frame) {
  if (frame.utime <= last_frame_utime_) {
    say(NodeEvent::Kind::kDropped, "camera frame at utime " + std::to_string(frame.utime) +
                                       (frame.utime == last_frame_utime_ ? " is a duplicate" : " is out of order"));
    return;
  }
  last_frame_utime_ = frame.utime;
  queued_frames_.push_back(frame);
  process_ready_frames(estimator_.propagator().latest_utime());
  while (static_cast<int>(queued_frames_.size()) > options_.max_queued_frames) {
    say(NodeEvent::Kind::kInfo, "IMU stalled: processing frame " + std::to_string(queued_frames_.front().utime) +
                                    " without IMU up to its time");
    process_frame(queued_frames_.front());
    queued_frames_.pop_front();
  }
}

void VinsNode::flush() {
  while (!queued_frames_.empty()) {
    process_frame(queued_frames_.front());
    queued_frames_.pop_front();
  }
}

void VinsNode::on_ground_truth(const GroundTruth& truth) {
  if (!options_.init_from_ground_truth || estimator_.initialized()) return;
  const estimator::InitialEstimate init = estimator::initial_estimate(truth, options_.vio, options_.perturb_seed);
  estimator_.initialize(init.value, truth.utime, init.P0);
  say(NodeEvent::Kind::kInfo, "initialised from ground truth at utime " + std::to_string(truth.utime));
}

void VinsNode::process_ready_frames(int64_t latest_imu_utime) {
  while (!queued_frames_.empty() && queued_frames_.front().utime <= latest_imu_utime) {
    process_frame(queued_frames_.front());
    queued_frames_.pop_front();
  }
}

void VinsNode::process_frame(const CameraFrame& frame) {
  if (before_frame_) before_frame_(frame);
  const estimator::FrameStatus status = estimator_.feed_camera(frame);
  switch (status) {
    case estimator::FrameStatus::kProcessed:
      publish_updated();
      if (after_update_) after_update_();
      return;
    case estimator::FrameStatus::kDiverged: {
      ++resets_;
      std::ostringstream msg;
      msg << "estimator diverged at utime " << frame.utime << " (" << estimator_.last_divergence().reason
          << "); reset, re-initialising " << (options_.init_from_ground_truth ? "from ground truth" : "at rest");
      estimator_.reset();
      say(NodeEvent::Kind::kError, msg.str());
      return;
    }
    case estimator::FrameStatus::kNotInitialized:
      say(NodeEvent::Kind::kDropped, "frame at utime " + std::to_string(frame.utime) + " before initialisation");
      return;
    default:
      say(NodeEvent::Kind::kDropped,
          "frame at utime " + std::to_string(frame.utime) + ": " + estimator::to_string(status));
      return;
  }
}

void VinsNode::publish_updated() {
  if (on_state_) on_state_(estimator::nav_state_of(estimator_, /*updated=*/true));
}

void VinsNode::publish_propagated(int64_t utime) {
  if (!on_state_ || !estimator_.initialized() || utime <= estimator_.state_utime()) return;
  // Output only: predicts the IMU marginal from the last update without
  // touching the filter, so IMU-rate output never changes the estimate.
  const estimator::ImuValue x0 = estimator_.imu_value();
  estimator::ImuValue x1;
  estimator::Matrix15d Phi, Q;
  estimator::PropagationReport report;
  if (!estimator_.propagator().predict_interval(x0, x0, estimator_.state_utime(), utime, &x1, &Phi, &Q, &report)) {
    return;
  }
  NavState s = estimator::nav_state_of(estimator_, /*updated=*/false);
  s.utime = utime;
  s.q_GtoI = x1.q_GtoI;
  s.p_IinG = x1.p_IinG;
  s.v_IinG = x1.v_IinG;
  s.bias_gyro = x1.bg;
  s.bias_accel = x1.ba;
  s.covariance = Phi * s.covariance * Phi.transpose() + Q;
  on_state_(s);
}

}  // namespace vimot

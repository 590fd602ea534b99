#include "procs/scale_estimator/scale_node.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/config/config.h"
#include "common/math/quat.h"
#include "common/target/target_output.h"

namespace vimot {

CameraPoseInWorld camera_pose_in_world(const Eigen::Vector4d& q_GtoI, const Eigen::Vector3d& p_IinG,
                                       const CameraCalibration& camera) {
  const Eigen::Matrix3d R_ItoG = quat_to_rot(q_GtoI).transpose();
  CameraPoseInWorld pose;
  pose.R_CtoG = R_ItoG * camera.R_ItoC.transpose();
  pose.p_CinG = p_IinG - R_ItoG * camera.R_ItoC.transpose() * camera.p_IinC;
  return pose;
}

void ScaleNodeOptions::validate() const {
  estimator.validate();
  if (max_pending < 1) throw std::invalid_argument("max_pending must be >= 1, got " + std::to_string(max_pending));
  if (!(estimate_period_s >= 0.0)) {
    throw std::invalid_argument("estimate_period_s must be >= 0, got " + std::to_string(estimate_period_s));
  }
  validate_object_filter();
}

void ScaleNodeOptions::validate_object_filter() const {
  filter.validate();
  if (!(prediction_horizon_s >= 0.0) || !std::isfinite(prediction_horizon_s)) {
    throw std::invalid_argument("prediction_horizon_s must be finite and >= 0");
  }
}

void object_filter_options_from_config(const Config& cfg, ScaleNodeOptions* options) {
  if (!cfg.has("object_filter")) return;
  cfg.check_keys("object_filter", {"sigma_v", "sigma_w", "k_lateral", "k_depth", "sigma_theta", "bias_sigma_theta",
                                   "bias_sigma_position", "scale_sigma", "scale_random_walk", "init_sigma_v",
                                   "init_sigma_w", "chi2_multiplier", "max_consecutive_rejections", "max_gap_s",
                                   "prediction_horizon_s"});
  const Config sec = cfg.sub("object_filter");
  target::ObjectPoseFilterOptions& f = options->filter;
  if (sec.has("sigma_v")) f.noise.sigma_v = Eigen::Vector3d::Constant(sec.get<double>("sigma_v"));
  if (sec.has("sigma_w")) f.noise.sigma_w = Eigen::Vector3d::Constant(sec.get<double>("sigma_w"));
  f.k_lateral = sec.get_or<double>("k_lateral", f.k_lateral);
  f.k_depth = sec.get_or<double>("k_depth", f.k_depth);
  if (sec.has("sigma_theta")) f.sigma_theta_C = sec.get_vec<3>("sigma_theta");
  f.bias_sigma_theta = sec.get_or<double>("bias_sigma_theta", f.bias_sigma_theta);
  f.bias_sigma_position = sec.get_or<double>("bias_sigma_position", f.bias_sigma_position);
  f.scale_sigma = sec.get_or<double>("scale_sigma", f.scale_sigma);
  f.scale_random_walk = sec.get_or<double>("scale_random_walk", f.scale_random_walk);
  f.init_sigma_v = sec.get_or<double>("init_sigma_v", f.init_sigma_v);
  f.init_sigma_w = sec.get_or<double>("init_sigma_w", f.init_sigma_w);
  f.chi2_multiplier = sec.get_or<double>("chi2_multiplier", f.chi2_multiplier);
  f.max_consecutive_rejections = sec.get_or<int>("max_consecutive_rejections", f.max_consecutive_rejections);
  f.max_gap_s = sec.get_or<double>("max_gap_s", f.max_gap_s);
  options->prediction_horizon_s = sec.get_or<double>("prediction_horizon_s", options->prediction_horizon_s);
  try {
    options->validate_object_filter();
  } catch (const std::invalid_argument& e) {
    cfg.fail("object_filter", e.what());
  }
}

ScaleNodeOptions scale_node_options_from_config(const Config& cfg) {
  cfg.check_keys("", {"calibration_file", "channels", "node", "object_filter", "scale_estimator"});
  cfg.check_keys("node", {"max_pending", "estimate_period_s"});
  ScaleNodeOptions o;
  o.estimator = scale::ScaleEstimatorOptions::from_config(cfg, "scale_estimator");
  const Config calib = Config::load_file(cfg.resolve_path(cfg.get<std::string>("calibration_file")));
  o.camera = camera_from_config(calib.sub("cameras.cam0"));
  o.max_pending = cfg.get_or<int>("node.max_pending", o.max_pending);
  o.estimate_period_s = cfg.get_or<double>("node.estimate_period_s", o.estimate_period_s);
  object_filter_options_from_config(cfg, &o);
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    cfg.fail("node", e.what());
  }
  return o;
}

ScaleNode::ScaleNode(const ScaleNodeOptions& options, ScaleCallback on_scale, PoseCallback on_pose,
                     EventCallback on_event, ObjectStateCallback on_object_state)
    : options_((options.validate(), options)),
      estimator_(options.estimator),
      on_scale_(std::move(on_scale)),
      on_pose_(std::move(on_pose)),
      on_event_(std::move(on_event)),
      on_object_state_(std::move(on_object_state)),
      filter_(options.filter) {}

void ScaleNode::say(NodeEvent::Kind kind, const std::string& message) {
  if (on_event_) on_event_(NodeEvent{kind, message});
}

bool ScaleNode::in_order(int64_t utime, std::optional<int64_t>* last, const char* channel) {
  if (*last && utime <= **last) {
    ++stats_.duplicate_or_backwards;
    say(NodeEvent::Kind::kDropped, std::string(channel) + (utime == **last ? " duplicate" : " went back in time") +
                                       " at utime " + std::to_string(utime));
    return false;
  }
  *last = utime;
  return true;
}

template <typename T>
void ScaleNode::drop_older(std::deque<T>* queue, int64_t utime, int64_t* counter, const char* what) {
  while (!queue->empty() && queue->front().utime < utime) {
    ++*counter;
    say(NodeEvent::Kind::kDropped, std::string(what) + " at utime " + std::to_string(queue->front().utime) +
                                       " never matched");
    queue->pop_front();
  }
}

void ScaleNode::on_nav_state(const NavState& state) {
  if (!state.updated) return;
  ++stats_.states_in;
  if (!in_order(state.utime, &last_state_utime_, "VINS state")) return;
  drop_older(&object_poses_, state.utime, &stats_.stale_object_poses, "object pose");
  if (!object_poses_.empty() && object_poses_.front().utime == state.utime) {
    const ObjectPoseEstimate pose = object_poses_.front();
    object_poses_.pop_front();
    process_pair(state, pose);
    return;
  }
  if (last_object_utime_ && *last_object_utime_ > state.utime) {
    ++stats_.stale_states;  // the tracker is past this frame: it skipped it
    say(NodeEvent::Kind::kDropped, "VINS state at utime " + std::to_string(state.utime) + " never matched");
    return;
  }
  states_.push_back(state);
  if (static_cast<int>(states_.size()) > options_.max_pending) {
    drop_older(&states_, states_[1].utime, &stats_.stale_states, "VINS state (queue full)");
  }
}

void ScaleNode::on_object_pose(const ObjectPoseEstimate& pose) {
  ++stats_.object_poses_in;
  if (!in_order(pose.utime, &last_object_utime_, "object pose")) return;
  drop_older(&states_, pose.utime, &stats_.stale_states, "VINS state");
  const bool state_waiting = !states_.empty() && states_.front().utime == pose.utime;
  if (!pose.valid) {
    ++stats_.invalid_object_poses;
    if (state_waiting) states_.pop_front();
    if (!estimator_.window().empty()) {
      say(NodeEvent::Kind::kInfo, "object tracking lost at utime " + std::to_string(pose.utime) + ": window cleared");
    }
    estimator_.clear_window();
    last_estimate_utime_.reset();
    return;
  }
  if (track_id_ && *track_id_ != pose.track_id) {
    ++stats_.new_tracks;
    say(NodeEvent::Kind::kInfo, "new object track " + std::to_string(pose.track_id) + " at utime " +
                                    std::to_string(pose.utime) + ": scale estimator and object filter reset");
    estimator_.reset();
    filter_.reset();
    last_estimate_utime_.reset();
  }
  track_id_ = pose.track_id;
  if (state_waiting) {
    const NavState state = states_.front();
    states_.pop_front();
    process_pair(state, pose);
    return;
  }
  if (last_state_utime_ && *last_state_utime_ > pose.utime) {
    ++stats_.stale_object_poses;  // VINS is past this frame: it skipped it
    say(NodeEvent::Kind::kDropped, "object pose at utime " + std::to_string(pose.utime) + " never matched");
    return;
  }
  object_poses_.push_back(pose);
  if (static_cast<int>(object_poses_.size()) > options_.max_pending) {
    drop_older(&object_poses_, object_poses_[1].utime, &stats_.stale_object_poses, "object pose (queue full)");
  }
}

void ScaleNode::process_pair(const NavState& state, const ObjectPoseEstimate& pose) {
  ++stats_.pairs;
  const CameraPoseInWorld camera = camera_pose_in_world(state.q_GtoI, state.p_IinG, options_.camera);
  scale::ScaleObservation obs;
  obs.utime = state.utime;
  obs.q_GtoC = rot_to_quat(camera.R_CtoG.transpose());
  obs.p_CinG = camera.p_CinG;
  obs.q_OtoC = pose.q_OtoC;
  obs.pbar_OinC = pose.pbar_OinC;

  const scale::AddStatus status = estimator_.add(obs);
  if (!scale::is_added(status)) {
    ++stats_.rejected_observations;
    say(NodeEvent::Kind::kDropped, std::string("pair at utime ") + std::to_string(obs.utime) +
                                       " rejected: " + scale::to_string(status));
    return;
  }
  if (status == scale::AddStatus::kAddedAfterGap) {
    say(NodeEvent::Kind::kInfo, "gap before utime " + std::to_string(obs.utime) + ": window cleared");
    last_estimate_utime_.reset();
  }

  const bool due = !last_estimate_utime_ ||
                   static_cast<double>(obs.utime - *last_estimate_utime_) * 1e-6 >= options_.estimate_period_s;
  if (due && static_cast<int>(estimator_.window().size()) >= options_.estimator.min_observations) {
    const scale::ScaleResult result = estimator_.update();
    last_estimate_utime_ = obs.utime;
    ++stats_.estimates;
    if (on_scale_) on_scale_(result);
  }
  if (const auto metric = estimator_.latest_object_pose()) {
    ++stats_.metric_poses;
    if (on_pose_) on_pose_(*metric);
    filter_pose(state, camera, *metric);
  }
}

void ScaleNode::filter_pose(const NavState& state, const CameraPoseInWorld& camera,
                            const scale::ObjectPoseInWorld& metric) {
  target::ObjectPoseMeasurement z;
  z.utime = metric.utime;
  z.q_GtoO = metric.q_GtoO;
  z.p_OinG = metric.p_OinG;
  z.p_OinC = metric.p_OinC;
  z.R_CtoG = camera.R_CtoG;
  z.scale = metric.scale;
  const target::ObjectFilterStatus status = filter_.add(z);
  if (!target::is_accepted(status)) {
    say(NodeEvent::Kind::kDropped, "object filter at utime " + std::to_string(z.utime) + ": " +
                                       target::to_string(status));
    return;
  }
  if (status == target::ObjectFilterStatus::kReinitialized) {
    say(NodeEvent::Kind::kInfo, "object filter re-initialised at utime " + std::to_string(z.utime));
  }
  ++stats_.object_states;
  if (!on_object_state_) return;
  const target::PoseValue imu{state.q_GtoI, state.p_IinG};
  on_object_state_(target::target_state_estimate(filter_.utime(), target::TargetRepresentation::kGlobal,
                                                 filter_.value(), filter_.covariance(), imu, 0, 1),
                   target::target_pose_prediction(filter_.utime(), options_.prediction_horizon_s,
                                                  filter_.predict(options_.prediction_horizon_s), imu));
}

}  // namespace vimot

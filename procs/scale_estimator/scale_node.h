#pragma once
// The `scale_estimator` process's logic without LCM: pairs the VINS camera
// pose and the tracker's up-to-scale object pose of the same camera frame,
// feeds ScaleEstimator, and says what to publish. main.cc only moves
// messages. Time is the messages' utime only (never the wall clock), so a
// live run and a log replay give the same output.
//
// Pairing: an updated VINS_STATE (camera rate) and an OBJECT_POSE_UPTOSCALE
// refer to the same camera frame iff their utimes are equal. Either may
// arrive first; the unmatched ones wait in two bounded queues. Each channel
// is in time order, so once one side has reached utime t, a waiting message
// of the other side older than t can never be matched: it is dropped as
// stale (counted). Per channel, a utime equal to the previous one is a
// duplicate and one before it goes backwards: both dropped and counted.
//
// Tracking loss: an invalid object pose clears the window (finite
// differences must not span the gap) but keeps the held scale. A new
// track_id means a re-initialised tracker whose length unit (the initial
// depth, scale paper Fig. 5) differs: window and held scale are reset.
// Within a track the last accepted scale is held until a new one is accepted.
//
// Object motion filter (common/target/object_pose_filter.h,
// docs/object_motion_filter.md): every metric pose is fed to a world-frame
// EKF whose accepted states (and a prediction prediction_horizon_s ahead)
// go to on_object_state. A new track_id resets it with the estimator: O and
// the length unit change. Tracking loss does not: the held scale and O
// stay valid, and a gap longer than the filter's max_gap_s re-initialises
// it from the next pose anyway (the filter's own, time-based rule).

#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "common/camera/camera_model.h"
#include "common/object/scale_estimator.h"
#include "common/process/node_event.h"
#include "common/target/object_pose_filter.h"
#include "common/types/nav_state.h"
#include "common/types/object_pose.h"
#include "common/types/target_state.h"

namespace vimot {

/// Camera pose in G from the IMU pose and the camera's extrinsics
/// (p_C = R_ItoC p_I + p_IinC):
///   R_CtoG = R_GtoI^T R_ItoC^T
///   p_CinG = p_IinG + R_GtoI^T p_CinI,   p_CinI = -R_ItoC^T p_IinC
struct CameraPoseInWorld {
  Eigen::Matrix3d R_CtoG{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_CinG{Eigen::Vector3d::Zero()};
};
CameraPoseInWorld camera_pose_in_world(const Eigen::Vector4d& q_GtoI, const Eigen::Vector3d& p_IinG,
                                       const CameraCalibration& camera);

struct ScaleNodeOptions {
  scale::ScaleEstimatorOptions estimator;
  /// The monocular camera (cam0); only its extrinsics R_ItoC, p_IinC are used.
  CameraCalibration camera;
  /// Unmatched messages kept per side (20 Hz camera: 10 = 0.5 s of latency).
  int max_pending{10};
  /// Estimate (and publish SCALE_ESTIMATE) at most every this many seconds
  /// of message time; 0 = for every pair.
  double estimate_period_s{0.0};
  /// The object motion filter and how far ahead its prediction looks.
  target::ObjectPoseFilterOptions filter;
  double prediction_horizon_s{0.5};  // s, as the target filter's TARGET_PREDICTION

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
  /// The part of validate() for filter and prediction_horizon_s.
  void validate_object_filter() const;
};

/// From a config/scale_estimator.yaml: `scale_estimator:` (the core's
/// options), `node:` (max_pending, estimate_period_s), `object_filter:`
/// (object_filter_options_from_config) and cam0 of
/// `calibration_file` (ASL layout, relative to the config's directory).
/// Throws ConfigError naming the file and key.
ScaleNodeOptions scale_node_options_from_config(const Config& cfg);

/// The optional `object_filter:` section into *options: sigma_v, sigma_w
/// (isotropic densities), k_lateral, k_depth, sigma_theta (3, per camera
/// axis), init_sigma_v, init_sigma_w, chi2_multiplier,
/// max_consecutive_rejections, max_gap_s, prediction_horizon_s. An unknown
/// key is a ConfigError.
void object_filter_options_from_config(const Config& cfg, ScaleNodeOptions* options);

struct ScaleNodeStats {
  int64_t states_in{0};            // updated VINS states received
  int64_t object_poses_in{0};
  int64_t pairs{0};                // matched by utime
  int64_t stale_states{0};         // dropped unmatched (other side passed them, or queue full)
  int64_t stale_object_poses{0};
  int64_t duplicate_or_backwards{0};
  int64_t invalid_object_poses{0};  // tracking lost: each one clears the window
  int64_t new_tracks{0};            // track_id changed: each one resets the estimator
  int64_t rejected_observations{0};  // pairs the core refused (non-finite, bad quaternion, time order)
  int64_t estimates{0};            // SCALE_ESTIMATE published
  int64_t metric_poses{0};         // OBJECT_POSE_METRIC published
  int64_t object_states{0};        // OBJECT_STATE (and OBJECT_PREDICTION) published
};

class ScaleNode {
 public:
  using ScaleCallback = std::function<void(const scale::ScaleResult&)>;
  using PoseCallback = std::function<void(const scale::ObjectPoseInWorld&)>;
  /// The filtered object (global representation, T = O; q_ItoT, p_TinI from
  /// the paired VINS pose) and its prediction, per accepted metric pose.
  using ObjectStateCallback = std::function<void(const TargetStateEstimate&, const TargetPosePrediction&)>;
  /// The event kinds of the estimator processes (info, dropped, error).
  using EventCallback = std::function<void(const NodeEvent&)>;

  /// Throws std::invalid_argument on invalid options.
  ScaleNode(const ScaleNodeOptions& options, ScaleCallback on_scale, PoseCallback on_pose,
            EventCallback on_event, ObjectStateCallback on_object_state = {});

  /// Only camera-rate states (updated = true) are used; IMU-rate ones are ignored.
  void on_nav_state(const NavState& state);
  void on_object_pose(const ObjectPoseEstimate& pose);

  const ScaleNodeStats& stats() const { return stats_; }
  const scale::ScaleEstimator& estimator() const { return estimator_; }
  const target::ObjectPoseFilter& filter() const { return filter_; }
  std::size_t pending_states() const { return states_.size(); }
  std::size_t pending_object_poses() const { return object_poses_.size(); }

 private:
  /// False (and counted) if `utime` repeats or precedes `last` of its channel.
  bool in_order(int64_t utime, std::optional<int64_t>* last, const char* channel);
  /// Drops queued messages older than `utime` (the other side passed them).
  template <typename T>
  void drop_older(std::deque<T>* queue, int64_t utime, int64_t* counter, const char* what);
  void process_pair(const NavState& state, const ObjectPoseEstimate& pose);
  void filter_pose(const NavState& state, const CameraPoseInWorld& camera, const scale::ObjectPoseInWorld& metric);
  void say(NodeEvent::Kind kind, const std::string& message);

  ScaleNodeOptions options_;
  scale::ScaleEstimator estimator_;
  ScaleCallback on_scale_;
  PoseCallback on_pose_;
  EventCallback on_event_;
  ObjectStateCallback on_object_state_;
  target::ObjectPoseFilter filter_;
  std::deque<NavState> states_;
  std::deque<ObjectPoseEstimate> object_poses_;
  std::optional<int64_t> last_state_utime_;
  std::optional<int64_t> last_object_utime_;
  std::optional<int64_t> track_id_;  // of the last valid object pose
  std::optional<int64_t> last_estimate_utime_;
  ScaleNodeStats stats_;
};

}  // namespace vimot

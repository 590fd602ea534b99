#pragma once
// The `target_filter` process's logic without LCM: the VIO estimator with the
// joint robot + target filter (common/target/target_filter.h) attached.
// It is a VinsNode (procs/vins/vins_node.h: the utime ordering, the robot's
// initialisation, resets) with the target filter attached to its estimator
// and two frame hooks: ground truth for the target's initialisation before
// a frame, the target outputs after it.
//
// Per processed frame it reports
//   * the robot state (NAV_STATE, nav_state_t, updated = true, as VINS_STATE);
//   * once the target is initialised: the target state (TARGET_STATE) and its
//     prediction prediction_horizon_s ahead (TARGET_PREDICTION) — also for
//     frames without target observations (the target is then only predicted).
// Initialisation: the robot as vins does; the target from its own features
// (target.init.mode features, no ground truth) or, in simulation, from the
// ground truth at the utime of the first frame with target observations
// (init.mode ground_truth: ground truth is buffered by utime for that).

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "common/config/config.h"
#include "common/estimator/vio_estimator.h"
#include "common/target/target_checkpoint.h"
#include "common/target/target_filter.h"
#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"
#include "common/types/sensor_data.h"
#include "common/types/target_state.h"

#include "procs/vins/vins_node.h"

namespace vimot {

struct TargetFilterNodeOptions {
  estimator::VioOptions vio;
  /// Target filter options (mode kOff: the target is only predicted).
  /// target_enabled false attaches no filter: pure VIO, no target outputs.
  target::TargetFilterOptions target;
  bool target_enabled{true};
  /// TARGET_PREDICTION is for utime + this (s, >= 0).
  double prediction_horizon_s{0.5};
  /// See VinsNodeOptions.
  bool init_from_ground_truth{true};
  uint64_t perturb_seed{0};
  /// Publish IMU-rate propagated robot states (NAV_STATE, updated = false).
  bool publish_imu_rate{false};
  int max_queued_frames{5};
  /// Ground truth kept for the target initialisation (s of history).
  double ground_truth_buffer_s{2.0};
  /// Input guards (`input` section of the vins config), see VinsNodeOptions.
  InputGuardOptions input;
  /// See VinsNodeOptions; with the target filter's state (target_checkpoint.h).
  std::string checkpoint_path;
  /// See VinsNodeOptions.
  std::string catch_up_log;
  CatchUpChannels catch_up_channels;
};

/// The process's options from config/target_filter.yaml:
///   vins_config: a vins config (calibration_file, init, estimator; relative
///     to this file) for the estimator and the start; without it those
///     sections are read from this file itself;
///   output.imu_rate;
///   target: common/target/target_filter_config.h (mode none: no filter
///     attached).
/// Throws ConfigError naming the file and key on a bad value or unknown key.
TargetFilterNodeOptions node_options_from_config(const Config& cfg);
/// Only the `target:` section, into *options.
void target_options_from_config(const Config& cfg, TargetFilterNodeOptions* options);

/// Input and processing events, as the vins process reports them.
using TargetFilterEvent = NodeEvent;

class TargetFilterNode {
 public:
  struct Callbacks {
    std::function<void(const NavState&)> on_nav_state;
    std::function<void(const TargetStateEstimate&)> on_target_state;
    std::function<void(const TargetPosePrediction&)> on_target_prediction;
    std::function<void(const TargetFilterEvent&)> on_event;
  };

  TargetFilterNode(const TargetFilterNodeOptions& options, Callbacks callbacks);
  ~TargetFilterNode();
  TargetFilterNode(const TargetFilterNode&) = delete;
  TargetFilterNode& operator=(const TargetFilterNode&) = delete;

  void on_imu(const ImuData& imu);
  void on_frame(const CameraFrame& frame);
  void on_ground_truth(const GroundTruth& truth);
  /// Processes every queued frame with the IMU data there is.
  void flush();
  /// See VinsNode::count_left.
  void count_left(EstimatorInput input, int64_t utime) { vins_.count_left(input, utime); }
  /// The robot part (VinsNode): resets, bridged gaps, restore.
  const VinsNode& vins() const { return vins_; }

  bool initialized() const { return vins_.initialized(); }
  bool target_initialized() const { return filter_ && filter_->initialized(); }
  int64_t frames_processed() const { return vins_.frames_processed(); }
  int64_t resets() const { return vins_.resets(); }
  const estimator::VioEstimator& estimator() const { return vins_.estimator(); }
  /// nullptr when target_enabled is false.
  const target::TargetFilter* filter() const { return filter_.get(); }
  /// The filter's part of the checkpoint (nullptr without a filter).
  const estimator::CheckpointExtension* checkpoint_extension() const { return checkpoint_.get(); }

 private:
  /// Buffers a usable ground truth (live or caught up) for the target's initialisation.
  void keep_truth(const GroundTruth& truth);
  void before_frame(const CameraFrame& frame);
  void after_update();

  TargetFilterNodeOptions options_;
  Callbacks callbacks_;
  VinsNode vins_;
  std::unique_ptr<target::TargetFilter> filter_;  // attached to vins_'s estimator
  std::unique_ptr<target::TargetCheckpoint> checkpoint_;  // filter_'s part of vins_'s checkpoint
  std::map<int64_t, GroundTruth> truths_;  // by utime, for the target initialisation
};

/// The target outputs of `filter` (initialised) at the estimator's state time.
TargetStateEstimate target_state_of(const estimator::VioEstimator& estimator, const target::TargetFilter& filter);
TargetPosePrediction target_prediction_of(const estimator::VioEstimator& estimator,
                                          const target::TargetFilter& filter, double horizon_s);

}  // namespace vimot

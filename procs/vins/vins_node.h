#pragma once
// The `vins` process's logic without LCM: orders its inputs by utime, feeds
// the estimator, initialises (from ground truth or at rest), resets on
// divergence, and says what to publish. main.cc only moves messages.
//
// Ordering rule (so a live run and a log replay give the same output): a
// camera frame is processed once an IMU sample at or after its utime has
// arrived, or when flush() is called (end of input, or the bounded wait of
// the process ran out). IMU samples are buffered by the estimator, so the
// frame sees exactly the IMU data up to its time however the two channels
// interleave on the network.

#include <cstdint>
#include <deque>
#include <functional>
#include <string>

#include "common/config/config.h"
#include "common/estimator/vio_estimator.h"
#include "common/process/node_event.h"
#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"
#include "common/types/sensor_data.h"

namespace vimot {

struct VinsNodeOptions {
  estimator::VioOptions vio;
  /// Start from ground truth (simulation): initialise at the first
  /// GROUND_TRUTH message, perturbed by a sample of the initial covariance
  /// drawn with this seed (0: exactly the truth).
  bool init_from_ground_truth{true};
  uint64_t perturb_seed{0};
  /// Publish the IMU-rate propagated state (VINS_STATE, updated = false).
  bool publish_imu_rate{true};
  /// Frames queued while waiting for IMU beyond this many are processed
  /// anyway (IMU stream stalled) — bounded memory and latency.
  int max_queued_frames{5};
};

/// The process's options from a vins config (config/vins.yaml, layout in
/// common/estimator/vins_config.h): estimator, init, output.imu_rate.
/// Throws ConfigError naming the file and key, also for an unknown key.
VinsNodeOptions vins_node_options_from_config(const Config& cfg);

class VinsNode {
 public:
  using StateCallback = std::function<void(const NavState&)>;
  using EventCallback = std::function<void(const NodeEvent&)>;

  VinsNode(const VinsNodeOptions& options, StateCallback on_state, EventCallback on_event);

  void on_imu(const ImuData& imu);
  void on_frame(const CameraFrame& frame);
  void on_ground_truth(const GroundTruth& truth);
  /// Processes every queued frame with the IMU data there is.
  void flush();

  /// Lets an extension of the process (the target filter) act around each
  /// frame: `before_frame` runs before the estimator sees a frame,
  /// `after_update` after a processed frame's updated state was published.
  void set_frame_hooks(std::function<void(const CameraFrame&)> before_frame, std::function<void()> after_update);

  bool initialized() const { return estimator_.initialized(); }
  int64_t frames_processed() const { return estimator_.frames_processed(); }
  int64_t resets() const { return resets_; }
  const estimator::VioEstimator& estimator() const { return estimator_; }
  /// For attaching an estimator extension (VioEstimator::set_extension).
  estimator::VioEstimator& mutable_estimator() { return estimator_; }

 private:
  void process_ready_frames(int64_t imu_utime);
  void process_frame(const CameraFrame& frame);
  void publish_updated();
  void publish_propagated(int64_t utime);
  void say(NodeEvent::Kind kind, const std::string& message);

  VinsNodeOptions options_;
  estimator::VioEstimator estimator_;
  StateCallback on_state_;
  EventCallback on_event_;
  std::function<void(const CameraFrame&)> before_frame_;
  std::function<void()> after_update_;
  std::deque<CameraFrame> queued_frames_;
  int64_t last_frame_utime_{-1};
  int64_t resets_{0};
};

}  // namespace vimot

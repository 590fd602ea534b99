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
//
// Input guards (InputGuardOptions, docs/robustness.md): absurd or mistimed
// input is dropped and said, lost input counted, and a moved source clock,
// an IMU gap, a wrong filter clock or an inconsistent filter resets the
// estimate, said as an error. No exception leaves a public call.

#include <cstdint>
#include <cstddef>
#include <deque>
#include <functional>
#include <string>

#include "common/config/config.h"
#include "common/estimator/checkpoint.h"
#include "common/estimator/vio_estimator.h"
#include "common/process/catch_up.h"
#include "common/process/node_event.h"
#include "common/process/stream_guard.h"
#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"
#include "common/types/sensor_data.h"

namespace vimot {

/// What the node accepts and when it resets (config section `input`,
/// docs/robustness.md). Defaults: no loss counting (rates unknown), limits
/// far outside clean input, so clean input is processed unchanged.
struct InputGuardOptions {
  StreamGuardOptions imu{0.0, 0.5, 0.5, 3};
  StreamGuardOptions features{0.0, 2.0, 0.5, 3};
  /// Ground truth (simulation): loss counting and jump rejection; a moved
  /// clock here only restarts this stream's clock (it does not feed the estimate).
  StreamGuardOptions ground_truth{0.0, 0.5, 0.5, 3};
  double max_gyro_radps{35.0};   // |ω| above: rejected (2000 °/s, a MEMS gyro's full scale)
  double max_accel_mps2{160.0};  // |a| above: rejected (16 g)
  /// A camera frame with an observation of an unknown camera, an undistorted
  /// coordinate |x| or |y| above `max_normalized` (a ray more than 84° off
  /// the axis at 10), or a pixel more than `max_pixels_outside` outside its
  /// camera's image (when the calibration gives a resolution) is corrupt:
  /// the whole frame is rejected.
  double max_normalized{10.0};
  double max_pixels_outside{100.0};
  /// A frame more than this after the newest IMU sample (IMU lost while
  /// frames continue), or propagated across a longer IMU gap: reset. Also
  /// how close to the IMU clock a ground truth must be to start from.
  double max_imu_gap_s{0.5};
  /// An outage of all input (e.g. the sensor driver restarted) up to this
  /// long is bridged instead of reset: the estimate, clones and landmarks
  /// are kept and propagated across it with the estimator's IMU gap noise
  /// (estimator.imu_gap_noise, required), and the first frames after it
  /// re-lock on the landmarks; an inconsistent result is caught by the χ²
  /// window below. Also the oldest checkpoint a start restores from.
  /// 0: every gap above max_imu_gap_s resets.
  double bridge_max_gap_s{0.0};
  /// Consecutive frames the estimator rejects as not after its state time
  /// (its clock is wrong, e.g. started from a future ground truth): reset.
  int max_rejected_frames{3};
  /// Filter consistency: over the last `consistency_window` processed frames
  /// with at least `consistency_min_tests` χ²-gated features, a fraction of
  /// gate failures above this (a consistent filter fails ≈ 5 % at the
  /// 95 % gate) means divergence: reset.
  int consistency_window{20};
  int consistency_min_tests{100};
  double max_chi2_failure_fraction{0.5};
  /// Ground-truth quaternion: |‖q‖ − 1| up to this is normalised, above it
  /// the message is rejected.
  double max_quat_norm_error{0.01};

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

/// `input` section of a vins / target_filter config.
InputGuardOptions input_guard_options_from_config(const Config& cfg);

/// Normalises a near-unit quaternion in place; false (with `why`) if it is
/// non-finite or further than `max_norm_error` from unit norm.
bool validate_quaternion(Eigen::Vector4d* q, double max_norm_error, std::string* why);

struct VinsNodeOptions {
  estimator::VioOptions vio;
  /// Start from ground truth (simulation): initialise at the first
  /// GROUND_TRUTH message, perturbed by a sample of the initial covariance
  /// drawn with this seed (0: exactly the truth).
  bool init_from_ground_truth{true};
  uint64_t perturb_seed{0};
  /// Publish the IMU-rate propagated state (VINS_STATE, updated = false).
  bool publish_imu_rate{true};
  /// ... every this many IMU samples (>= 1), counted from each update (so
  /// a node restored from its checkpoint publishes the same ones). Each carries a full 15×15
  /// covariance (≈ 2 kB) into every subscriber's socket; the camera-rate
  /// consumers (scale_estimator, log evaluation) need only updated states.
  int imu_rate_every{1};
  /// Frames queued while waiting for IMU beyond this many are processed
  /// anyway (IMU stream stalled) — bounded memory and latency.
  int max_queued_frames{5};
  InputGuardOptions input;
  /// If set: the estimator's whole state is written there after every
  /// update (common/estimator/checkpoint.h), and a start goes on from it
  /// when it is at most input.bridge_max_gap_s older than the first input,
  /// bridging the gap (a respawned process). Empty: no checkpoint.
  std::string checkpoint_path;
  /// With a checkpoint: the run's LCM log (vimot-logger's). A restore at
  /// the first input first handles, from this log, the input the process
  /// missed (after the checkpoint's state, up to that first input), so the
  /// estimate goes on as if it had never stopped; what the log lacks is
  /// bridged. Empty: the gap is bridged.
  std::string catch_up_log;
  CatchUpChannels catch_up_channels;
};

/// The process's options from a vins config (config/vins.yaml, layout in
/// common/estimator/vins_config.h): estimator, init, output.imu_rate.
/// Throws ConfigError naming the file and key, also for an unknown key.
VinsNodeOptions vins_node_options_from_config(const Config& cfg);

/// ConfigError if input.bridge_max_gap_s is set without the estimator's
/// IMU gap noise (a bridge must grow the covariance).
void check_bridge_options(const InputGuardOptions& input, const estimator::VioOptions& vio, const Config& cfg);

class VinsNode {
 public:
  using StateCallback = std::function<void(const NavState&)>;
  using EventCallback = std::function<void(const NodeEvent&)>;

  VinsNode(const VinsNodeOptions& options, StateCallback on_state, EventCallback on_event);

  void on_imu(const ImuData& imu);
  void on_frame(const CameraFrame& frame);
  /// True if the message was usable (it then went to the ground-truth
  /// hook with unit quaternions); false, said as dropped, if not.
  bool on_ground_truth(const GroundTruth& truth);
  /// Processes every queued frame with the IMU data there is.
  void flush();
  /// A message of `input` left unhandled at the stop (the process counts it
  /// lost): the messages missing before it, after the last handled or left
  /// one, are counted lost as a gap between handled messages is.
  void count_left(EstimatorInput input, int64_t utime);

  /// Lets an extension of the process (the target filter) act around each
  /// frame: `before_frame` runs before the estimator sees a frame,
  /// `after_update` after a processed frame's updated state was published.
  void set_frame_hooks(std::function<void(const CameraFrame&)> before_frame, std::function<void()> after_update);
  /// Runs on each usable ground truth (unit quaternions), live or caught up.
  void set_ground_truth_hook(std::function<void(const GroundTruth&)> on_truth) { on_truth_ = std::move(on_truth); }
  /// The attached extension's part of the checkpoint (not owned; set before any input).
  void set_checkpoint_extension(estimator::CheckpointExtension* extension) { checkpoint_extension_ = extension; }

  bool initialized() const { return estimator_.initialized(); }
  int64_t frames_processed() const { return estimator_.frames_processed(); }
  int64_t resets() const { return resets_; }
  /// Input outages propagated across instead of reset (bridge_max_gap_s).
  int64_t bridged_gaps() const { return bridged_gaps_; }
  /// True once the estimate was restored from the checkpoint.
  bool restored() const { return restored_; }
  /// Messages of `input` handled from the catch-up log.
  int64_t caught_up(EstimatorInput input) const { return caught_up_[index(input)]; }
  /// Live messages not handled again: the checkpoint's state or the catch-up had them.
  int64_t already_handled() const { return already_handled_; }
  /// The input stream's timing guard (its lost and rejected counts).
  const StreamGuard& guard(EstimatorInput input) const;
  /// Validates a ground-truth message's values in place (quaternions
  /// normalised); false, said as dropped, if it is unusable.
  bool check_ground_truth(GroundTruth* truth);
  /// Empty if every observation of `frame` is possible for the calibrated
  /// cameras, else why not (input.max_normalized, max_pixels_outside).
  std::string absurd_observation(const CameraFrame& frame) const;
  const estimator::VioEstimator& estimator() const { return estimator_; }
  /// For attaching an estimator extension (VioEstimator::set_extension).
  estimator::VioEstimator& mutable_estimator() { return estimator_; }

 private:
  void process_ready_frames(int64_t imu_utime);
  void process_frame(const CameraFrame& frame);
  void publish_updated();
  void publish_propagated(int64_t utime);
  void say(NodeEvent::Kind kind, const std::string& message);
  /// Runs `body`; an exception is said and resets the estimator, it never
  /// leaves a callback.
  template <typename F>
  void guarded(const char* where, F&& body);
  /// Drops the estimate (and, on a source reset, the IMU buffer, queued
  /// frames and every stream clock) and says so; re-initialisation follows.
  void reset_estimate(const std::string& why, bool clean_clock);
  /// Applies a stream guard's verdict; false if the message is to be dropped.
  bool admit(StreamGuard& guard, int64_t utime);
  static std::size_t index(EstimatorInput input) { return static_cast<std::size_t>(input); }
  /// Before each input: at the first, the restore and catch-up
  /// (--catch-up-log); false if the message was handled already.
  bool enter(EstimatorInput input, int64_t utime);
  /// Handles the logged input after the checkpoint's state `c` up to the
  /// first live message (`live` at `live_utime`), in log order; says what
  /// it did and what the log lacks.
  void catch_up(const estimator::EstimatorCheckpoint& c, EstimatorInput live, int64_t live_utime);
  /// `publish`: false for a sample the process had before its checkpoint's
  /// update (its IMU-rate output was published from the state before).
  void on_imu_checked(const ImuData& imu, bool publish);
  bool on_ground_truth_checked(const GroundTruth& message);
  void on_frame_checked(const CameraFrame& frame);
  void check_consistency();
  void initialise_from(const GroundTruth& truth);
  /// At the first input only: restores the checkpoint if it is usable and
  /// at most bridge_max_gap_s before `input_utime`; says what it did.
  void try_restore(int64_t input_utime);
  /// The restore of try_restore into *c; says why not, or that it restored
  /// and what comes `next`.
  bool restore_checkpoint(int64_t input_utime, const std::string& next, estimator::EstimatorCheckpoint* c);
  void write_checkpoint();
  /// True (said) if a step of `gap_s` forward in the input is bridged.
  bool bridges(double gap_s, const std::string& what);

  VinsNodeOptions options_;
  estimator::VioEstimator estimator_;
  StateCallback on_state_;
  EventCallback on_event_;
  std::function<void(const CameraFrame&)> before_frame_;
  std::function<void()> after_update_;
  std::function<void(const GroundTruth&)> on_truth_;
  estimator::CheckpointExtension* checkpoint_extension_{nullptr};
  std::deque<CameraFrame> queued_frames_;
  int64_t last_frame_utime_{-1};
  int64_t resets_{0};
  int64_t bridged_gaps_{0};
  bool restore_tried_{false};
  bool restored_{false};
  int64_t caught_up_[3]{0, 0, 0};
  /// Per input: the newest utime handled before or in the catch-up.
  int64_t caught_until_[3]{INT64_MIN, INT64_MIN, INT64_MIN};
  int64_t already_handled_{0};
  bool checkpoint_failed_{false};  // said once
  StreamGuard imu_guard_;
  StreamGuard frame_guard_;
  StreamGuard truth_guard_;
  int rejected_frames_{0};
  int64_t imu_rate_count_{0};
  struct GateCounts {
    int tested{0};
    int failed{0};
  };
  std::deque<GateCounts> gate_window_;
};

}  // namespace vimot

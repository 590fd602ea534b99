#pragma once
// Stereo MSCKF visual-inertial estimator (OpenVINS VioManager-like): IMU
// propagation, clone window, MSCKF and SLAM updates of static-scene
// features, static or ground-truth initialisation, divergence reporting.
// Observations flagged is_target are ignored here (the target filter takes
// them). Deterministic: the output depends only on the input sequence.
//
// Per camera frame at time t:
//   propagate to t and clone; sort observations into SLAM landmarks and the
//   feature database; MSCKF update with tracks that ended before t and, once
//   the window is full, tracks seen at the clone about to leave (those seen
//   in >= num_clones frames become SLAM candidates if slots are free); SLAM
//   update; SLAM delayed initialisation; anchor change of the anchored
//   landmarks at the leaving clone; marginalise lost SLAM landmarks and the
//   oldest clone; divergence check.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/camera/camera_model.h"
#include "common/estimator/feature_database.h"
#include "common/estimator/measurement_model.h"
#include "common/estimator/propagator.h"
#include "common/estimator/state.h"
#include "common/estimator/static_initializer.h"
#include "common/estimator/triangulation.h"
#include "common/estimator/updater_common.h"
#include "common/estimator/updater_msckf.h"
#include "common/estimator/updater_slam.h"
#include "common/estimator/vio_extension.h"
#include "common/types/sensor_data.h"

namespace vimot {

class Config;

namespace estimator {

enum class InitMode { kGroundTruth, kStatic };

/// Initial standard deviations of the IMU state (used by initialize(x, t)
/// and by static initialisation).
struct InitSigmas {
  double theta_rp{0.01};  // rad, roll/pitch
  double theta_yaw{0.01}; // rad
  double p{0.01};         // m
  double v{0.05};         // m/s
  double bg{0.005};       // rad/s
  double ba{0.05};        // m/s²
};

/// P0 of VioEstimator::initialize(value, utime) for an IMU orientation
/// q_GtoI: roll/pitch and yaw σ are about G's axes, rotated into the
/// IMU-frame orientation error; position, velocity, biases isotropic.
Matrix15d initial_covariance(const Eigen::Vector4d& q_GtoI, const InitSigmas& sigmas);

struct DivergenceOptions {
  double max_position_correction_m{2.0};  // |Δp| of one frame's updates
  double max_velocity_mps{100.0};
};

struct VioOptions {
  StateOptions state;                 // num_clones, max_slam, use_fej, slam_representation
  PropagatorOptions propagator;       // IMU noise, gravity, gap threshold
  MsckfOptions msckf;
  SlamOptions slam;
  TriangulationOptions triangulation;
  StaticInitOptions static_init;
  InitSigmas init_sigmas;
  DivergenceOptions divergence;
  InitMode init_mode{InitMode::kGroundTruth};
  std::vector<CameraCalibration> cameras;  // cam0 (left), cam1 (right)
  bool use_stereo{true};                   // use cam1 observations
  double sigma_px{1.0};                    // pixel noise (1σ)

  /// Estimator keys from `section` of `estimator_cfg` (every key optional,
  /// defaults as above); cameras from calibration_cfg "cameras.cam0" /
  /// "cameras.cam1" (ASL layout) and IMU noise from its "imu.*" keys if
  /// present. Throws ConfigError naming the offending key.
  static VioOptions from_config(const Config& estimator_cfg, const Config& calibration_cfg,
                                const std::string& section = "estimator");
  /// Both from one configuration.
  static VioOptions from_config(const Config& cfg, const std::string& section = "estimator");

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

enum class FrameStatus {
  kProcessed,
  kNotInitialized,      // dropped: no initial state yet
  kRejectedOutOfOrder,  // not after the state time
  kNoImu,               // no IMU data to propagate with; dropped
  kDiverged,            // estimator has diverged; call reset()
};
const char* to_string(FrameStatus status);

/// Cost of the last processed frame (benchmarks only; it never influences
/// the estimate): wall-clock per stage and in total, and the CPU time of the
/// calling thread in total (meaningful on a loaded machine).
struct FrameTiming {
  double propagate_ms{0.0};
  double msckf_ms{0.0};
  double slam_update_ms{0.0};
  double slam_init_ms{0.0};
  double marginalize_ms{0.0};
  double total_ms{0.0};
  double total_cpu_ms{0.0};
};

struct DivergenceReport {
  int64_t utime{0};
  std::string reason;
};

class VioEstimator {
 public:
  explicit VioEstimator(const VioOptions& options);

  /// Buffers an IMU sample (and runs static initialisation if configured).
  ImuFeedStatus feed_imu(const ImuData& imu);

  /// Processes one synchronised stereo frame of feature observations.
  FrameStatus feed_camera(const CameraFrame& frame);

  /// Initialises at utime with the given IMU state and init_sigmas.
  void initialize(const ImuValue& value, int64_t utime);
  /// ... with an explicit 15×15 covariance (order [δθ δp δv δbg δba]).
  void initialize(const ImuValue& value, int64_t utime, const Matrix15d& P_imu);

  /// Back to uninitialised: state, window, landmarks and tracks dropped;
  /// the IMU buffer is kept.
  void reset();
  /// Also drops the buffered IMU data (a source whose clock moved).
  void clear_imu() { propagator_.clear(); }
  /// An IMU reading older than every buffered one (a restored state's, see
  /// checkpoint.h); false if it is not older.
  bool prepend_imu(const ImuData& imu) { return propagator_.prepend(imu); }
  /// Initialised with a whole state and its MSCKF tracks (a checkpoint's,
  /// checkpoint.h); the extension, if any, takes its part afterwards.
  void restore(std::unique_ptr<State> state, FeatureDatabase tracks);
  /// The MSCKF feature tracks.
  const FeatureDatabase& tracks() const { return database_; }

  /// Called once per divergence detection (covariance non-finite or with a
  /// negative diagonal, non-finite state, too large a correction, too high a
  /// speed, or an internal error).
  void set_divergence_callback(std::function<void(const DivergenceReport&)> callback) {
    divergence_callback_ = std::move(callback);
  }

  bool initialized() const { return initialized_; }
  bool diverged() const { return diverged_; }
  const DivergenceReport& last_divergence() const { return last_divergence_; }

  int64_t state_utime() const { return state_->utime(); }
  ImuValue imu_value() const { return state_->imu()->get(); }
  Matrix15d imu_covariance() const;
  /// Current estimates of the window poses, oldest first.
  ClonePoses clone_poses() const;
  const State& state() const { return *state_; }
  /// For extensions (target filter) that add variables to the same state.
  State& mutable_state() { return *state_; }
  /// Attaches an extension (not owned; nullptr detaches). See
  /// vio_extension.h for the calls it gets. Without one the estimator's
  /// behaviour is unchanged; with one, is_target observations go to it
  /// (they are still counted in target_observations_ignored()).
  void set_extension(VioExtension* extension) { extension_ = extension; }
  VioExtension* extension() const { return extension_; }
  const Propagator& propagator() const { return propagator_; }
  const std::vector<CameraInfo>& cameras() const { return cameras_; }
  const VioOptions& options() const { return options_; }

  const UpdateStats& last_stats() const { return last_stats_; }
  const UpdateStats& total_stats() const { return total_stats_; }
  const FrameTiming& last_timing() const { return last_timing_; }
  int64_t frames_processed() const { return frames_processed_; }
  int64_t frames_dropped() const { return frames_dropped_; }
  int64_t target_observations_ignored() const { return target_obs_ignored_; }
  int64_t invalid_observations() const { return invalid_obs_; }
  const PropagationReport& last_propagation() const { return last_propagation_; }

 private:
  void process_frame(const CameraFrame& frame);
  bool check_health(const Eigen::Vector3d& p_before);
  void report_divergence(const std::string& reason);

  VioOptions options_;
  std::vector<CameraInfo> cameras_;
  std::unique_ptr<State> state_;
  Propagator propagator_;
  UpdaterMsckf msckf_;
  UpdaterSlam slam_;
  StaticInitializer static_init_;
  FeatureDatabase database_;
  VioExtension* extension_{nullptr};

  bool initialized_{false};
  bool diverged_{false};
  DivergenceReport last_divergence_;
  std::function<void(const DivergenceReport&)> divergence_callback_;

  UpdateStats last_stats_;
  UpdateStats total_stats_;
  FrameTiming last_timing_;
  PropagationReport last_propagation_;
  int64_t frames_processed_{0};
  int64_t frames_dropped_{0};
  int64_t target_obs_ignored_{0};
  int64_t invalid_obs_{0};
};

}  // namespace estimator
}  // namespace vimot

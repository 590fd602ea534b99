#pragma once
// The simulator: IMU samples, camera frames and ground truth of one
// scenario as a time-ordered event stream, plus the truth an evaluator needs.
//
// Timing: sample k of a sensor at rate f has utime = start_utime +
// round(k 1e6 / f) µs, computed from the integer k (no drift); where the
// rates divide (200 Hz / 10 Hz) camera frames fall exactly on IMU samples.
// All truth is evaluated at the stamped time t = (utime - start_utime) 1e-6 s.
// At equal utime the events come as ImuSample, GroundTruth, CameraFrame, so
// a consumer has the IMU data up to a frame before the frame.
//
// Determinism: the output is a function of the SimConfig only (seed for the
// noise streams, map_seed for the map); no wall clock, no global state.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "common/sim/bspline_se3.h"
#include "common/sim/feature_simulator.h"
#include "common/sim/imu_simulator.h"
#include "common/sim/scenarios.h"
#include "common/sim/sim_config.h"
#include "common/sim/sim_types.h"

namespace vimot {
namespace sim {

class Simulator {
 public:
  /// Validates the config (std::invalid_argument naming the field), builds
  /// the scenario (may read the trajectory file: std::runtime_error) and the
  /// map. Emission starts at start_utime.
  explicit Simulator(const SimConfig& config);

  /// The next event in time order; std::nullopt once all are emitted.
  std::optional<SimEvent> next();

  /// Calls `callback` with every remaining event in order.
  void run(const std::function<void(const SimEvent&)>& callback);

  // ---- timing --------------------------------------------------------------
  int64_t start_utime() const { return config_.start_utime; }
  /// Last utime any event may carry (start + duration, whole µs).
  int64_t end_utime() const { return config_.start_utime + duration_us_; }
  double duration() const { return static_cast<double>(duration_us_) * 1e-6; }
  /// Seconds since start_utime.
  double sim_time(int64_t utime) const;
  int64_t imu_sample_count() const { return n_imu_; }
  int64_t camera_frame_count() const { return n_cam_; }
  int64_t imu_utime(int64_t k) const;
  int64_t camera_utime(int64_t k) const;

  // ---- truth ---------------------------------------------------------------
  /// IMU pose and exact derivatives at sim time t in [0, duration()] (s).
  SplineState robot_state(double t) const;
  bool has_target() const { return motion_.target.has_value(); }
  /// Target (box centre T) pose and derivatives; std::nullopt without target.
  std::optional<SplineState> target_state(double t) const;
  /// Ground truth at a utime, with the given bias values.
  GroundTruth ground_truth(int64_t utime, const Eigen::Vector3d& bias_gyro, const Eigen::Vector3d& bias_accel) const;
  /// Ground truth at start_utime with the initial biases (start-from-truth).
  GroundTruth initial_state() const;
  /// Length of the IMU's path over the run (m), from 100 Hz samples.
  double path_length() const { return path_length_; }
  const BsplineSE3& robot_spline() const { return motion_.robot; }
  /// Spline time of sim time 0 (the splines' own time axis).
  double spline_time_offset() const { return motion_.t_begin; }
  const Eigen::AlignedBox2d& workspace() const { return motion_.workspace; }

  /// Static and target points so far (spawned points are appended as the
  /// run goes); landmarks()[k].id == k.
  const std::vector<Landmark>& landmarks() const { return features_->landmarks(); }
  /// The landmark (3D point) a feature id (track) belongs to, -1 if never
  /// issued. Truth for evaluation and tests: a front end cannot know it.
  int64_t landmark_of_feature(int64_t feature_id) const { return features_->landmark_of_feature(feature_id); }
  const std::vector<CameraCalibration>& cameras() const { return config_.camera.calibrations; }
  const std::vector<CameraModel>& camera_models() const { return features_->cameras(); }
  /// IMU rate, noise densities, random walks, initial biases, gravity.
  const ImuSimConfig& imu_config() const { return config_.imu; }
  const SimConfig& config() const { return config_; }

 private:
  void refill();

  SimConfig config_;
  ScenarioMotion motion_;
  int64_t duration_us_{0};
  int64_t n_imu_{0};
  int64_t n_cam_{0};
  double path_length_{0.0};

  ImuSimulator imu_;
  std::unique_ptr<FeatureSimulator> features_;
  int64_t next_imu_{0};
  int64_t next_cam_{0};
  std::vector<SimEvent> pending_;  // events of the current tick, in order
  std::size_t pending_pos_{0};
};

}  // namespace sim
}  // namespace vimot

#include "common/sim/simulator.h"

#include <cmath>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot {
namespace sim {

namespace {

constexpr uint64_t kStreamImu = 10;
// Sampling step (s) of the path-length sum.
constexpr double kPathSampleDt = 0.01;

const SimConfig& validated(const SimConfig& config) {
  validate(config);
  return config;
}

// Offset (µs) of sample k of a sensor at `rate_hz`, rounded from k exactly.
int64_t tick_offset(int64_t k, double rate_hz) {
  return static_cast<int64_t>(std::llround(static_cast<double>(k) * 1e6 / rate_hz));
}

// Number of samples with offset <= duration_us.
int64_t tick_count(int64_t duration_us, double rate_hz) {
  int64_t n = static_cast<int64_t>(std::floor(static_cast<double>(duration_us) * rate_hz * 1e-6)) + 1;
  while (n > 0 && tick_offset(n - 1, rate_hz) > duration_us) --n;
  while (tick_offset(n, rate_hz) <= duration_us) ++n;
  return n;
}

}  // namespace

Simulator::Simulator(const SimConfig& config)
    : config_(validated(config)),
      motion_(make_scenario(config_)),
      imu_(config_.imu, derive_seed(config_.seed, kStreamImu)) {
  // Whole microseconds inside the splines' range (1 ns slack for rounding).
  duration_us_ = static_cast<int64_t>(std::floor(motion_.duration * 1e6 + 1e-3));
  n_imu_ = tick_count(duration_us_, config_.imu.rate_hz);
  n_cam_ = tick_count(duration_us_, config_.camera.rate_hz);
  features_ = std::make_unique<FeatureSimulator>(config_.camera, config_.map, config_.target, has_target(),
                                                 motion_.workspace, config_.seed, config_.map_seed);
  const int64_t n_path = static_cast<int64_t>(std::ceil(duration() / kPathSampleDt));
  Eigen::Vector3d prev = robot_state(0.0).p_BinG;
  for (int64_t k = 1; k <= n_path; ++k) {
    const double t = std::min(duration(), static_cast<double>(k) * kPathSampleDt);
    const Eigen::Vector3d p = motion_.robot.pose(motion_.t_begin + t).topRightCorner<3, 1>();
    path_length_ += (p - prev).norm();
    prev = p;
  }
}

double Simulator::sim_time(int64_t utime) const {
  return static_cast<double>(utime - config_.start_utime) * 1e-6;
}

int64_t Simulator::imu_utime(int64_t k) const { return config_.start_utime + tick_offset(k, config_.imu.rate_hz); }

int64_t Simulator::camera_utime(int64_t k) const {
  return config_.start_utime + tick_offset(k, config_.camera.rate_hz);
}

SplineState Simulator::robot_state(double t) const {
  SplineState s = motion_.robot.evaluate(motion_.t_begin + t);
  s.t = t;
  return s;
}

std::optional<SplineState> Simulator::target_state(double t) const {
  if (!motion_.target) return std::nullopt;
  SplineState s = motion_.target->evaluate(motion_.t_begin + t);
  s.t = t;
  return s;
}

GroundTruth Simulator::ground_truth(int64_t utime, const Eigen::Vector3d& bias_gyro,
                                    const Eigen::Vector3d& bias_accel) const {
  const double t = sim_time(utime);
  const SplineState r = robot_state(t);
  GroundTruth gt;
  gt.utime = utime;
  gt.q_GtoI = rot_to_quat(r.R_BtoG.transpose());
  gt.p_IinG = r.p_BinG;
  gt.v_IinG = r.v_BinG;
  gt.w_IinI = r.w_BinB;
  gt.a_IinG = r.a_BinG;
  gt.bias_gyro = bias_gyro;
  gt.bias_accel = bias_accel;
  if (const auto target = target_state(t)) {
    gt.has_target = true;
    gt.q_GtoT = rot_to_quat(target->R_BtoG.transpose());
    gt.p_TinG = target->p_BinG;
    gt.v_TinT = target->R_BtoG.transpose() * target->v_BinG;
    gt.w_TinT = target->w_BinB;
  }
  return gt;
}

GroundTruth Simulator::initial_state() const {
  return ground_truth(config_.start_utime, config_.imu.initial_gyro_bias, config_.imu.initial_accel_bias);
}

void Simulator::refill() {
  pending_.clear();
  pending_pos_ = 0;
  const bool imu_left = next_imu_ < n_imu_;
  const bool cam_left = next_cam_ < n_cam_;
  if (!imu_left && !cam_left) return;
  const int64_t t_imu = imu_left ? imu_utime(next_imu_) : 0;
  const int64_t t_cam = cam_left ? camera_utime(next_cam_) : 0;
  if (imu_left && (!cam_left || t_imu <= t_cam)) {
    const SplineState truth = robot_state(sim_time(t_imu));
    // Truth carries the biases the sample is measured with.
    const Eigen::Vector3d bg = imu_.bias_gyro(), ba = imu_.bias_accel();
    ImuSample sample;
    sample.utime = t_imu;
    imu_.measure(truth, &sample.w_IinI, &sample.a_IinI);
    pending_.emplace_back(sample);
    if (config_.ground_truth_events) pending_.emplace_back(ground_truth(t_imu, bg, ba));
    ++next_imu_;
  } else {
    const double t = sim_time(t_cam);
    const Eigen::Matrix4d T_ItoG = motion_.robot.pose(motion_.t_begin + t);
    if (motion_.target) {
      const Eigen::Matrix4d T_TtoG = motion_.target->pose(motion_.t_begin + t);
      pending_.emplace_back(features_->simulate(t_cam, T_ItoG, &T_TtoG));
    } else {
      pending_.emplace_back(features_->simulate(t_cam, T_ItoG, nullptr));
    }
    ++next_cam_;
  }
}

std::optional<SimEvent> Simulator::next() {
  if (pending_pos_ >= pending_.size()) refill();
  if (pending_pos_ >= pending_.size()) return std::nullopt;
  return std::move(pending_[pending_pos_++]);
}

void Simulator::run(const std::function<void(const SimEvent&)>& callback) {
  while (auto event = next()) callback(*event);
}

}  // namespace sim
}  // namespace vimot

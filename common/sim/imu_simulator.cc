#include "common/sim/imu_simulator.h"

#include <cmath>

namespace vimot {
namespace sim {

ImuSimulator::ImuSimulator(const ImuSimConfig& config, uint64_t seed)
    : config_(config),
      dt_(1.0 / config.rate_hz),
      gravity_G_(0.0, 0.0, -config.gravity),
      bias_gyro_(config.initial_gyro_bias),
      bias_accel_(config.initial_accel_bias),
      rng_(seed) {}

Eigen::Vector3d ImuSimulator::gaussian3() {
  // Drawn one by one in x, y, z order: the sequence is fixed by the seed.
  const double x = normal_(rng_);
  const double y = normal_(rng_);
  const double z = normal_(rng_);
  return Eigen::Vector3d(x, y, z);
}

Eigen::Vector3d ImuSimulator::specific_force(const SplineState& truth) const {
  return truth.R_BtoG.transpose() * (truth.a_BinG - gravity_G_);
}

void ImuSimulator::measure(const SplineState& truth, Eigen::Vector3d* gyro, Eigen::Vector3d* accel) {
  *gyro = truth.w_BinB + bias_gyro_;
  *accel = specific_force(truth) + bias_accel_;
  if (!config_.noise) return;
  const double sqrt_dt = std::sqrt(dt_);
  *gyro += config_.gyroscope_noise_density / sqrt_dt * gaussian3();
  *accel += config_.accelerometer_noise_density / sqrt_dt * gaussian3();
  bias_gyro_ += config_.gyroscope_random_walk * sqrt_dt * gaussian3();
  bias_accel_ += config_.accelerometer_random_walk * sqrt_dt * gaussian3();
}

}  // namespace sim
}  // namespace vimot

#pragma once
// IMU measurement model (the discrete form of the continuous-time model used
// by OpenVINS and Trawny & Roumeliotis), for sample period Δt = 1 / rate:
//
//   ω_m = ω_I + b_g + n_g,      n_g ~ N(0, σ_g² / Δt)
//   a_m = R_GtoI (a_G - g) + b_a + n_a,   g = [0, 0, -gravity],  n_a ~ N(0, σ_a² / Δt)
//   b_{k+1} = b_k + σ_bg √Δt n,  n ~ N(0, I)   (same for b_a with σ_ba)
//
// σ_g, σ_a are the noise densities, σ_bg, σ_ba the random walks. Sample k
// uses the biases b_k (reported as truth with it), then the biases step.

#include <Eigen/Core>
#include <random>

#include "common/sim/bspline_se3.h"
#include "common/sim/sim_config.h"

namespace vimot {
namespace sim {

class ImuSimulator {
 public:
  ImuSimulator(const ImuSimConfig& config, uint64_t seed);

  /// Measurement of the true motion `truth` of I (spline state) with the
  /// current biases; afterwards the biases take one random-walk step.
  void measure(const SplineState& truth, Eigen::Vector3d* gyro, Eigen::Vector3d* accel);

  /// Biases that the next measure() uses.
  const Eigen::Vector3d& bias_gyro() const { return bias_gyro_; }
  const Eigen::Vector3d& bias_accel() const { return bias_accel_; }

  /// Noise-free specific force of `truth` in I: R_GtoI (a_G - g).
  Eigen::Vector3d specific_force(const SplineState& truth) const;

 private:
  Eigen::Vector3d gaussian3();

  ImuSimConfig config_;
  double dt_{0.0};
  Eigen::Vector3d gravity_G_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d bias_gyro_{Eigen::Vector3d::Zero()};
  Eigen::Vector3d bias_accel_{Eigen::Vector3d::Zero()};
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace sim
}  // namespace vimot

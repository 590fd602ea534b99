#include "common/eval/initial_estimate.h"

#include <Eigen/Cholesky>
#include <random>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot {
namespace eval {

estimator::Matrix15d initial_covariance(const Eigen::Vector4d& q_GtoI, const estimator::InitSigmas& s) {
  estimator::Matrix15d P = estimator::Matrix15d::Zero();
  const Eigen::Matrix3d R = quat_to_rot(quat_normalize(q_GtoI));
  const Eigen::Vector3d dg(s.theta_rp * s.theta_rp, s.theta_rp * s.theta_rp, s.theta_yaw * s.theta_yaw);
  P.block<3, 3>(0, 0) = R * dg.asDiagonal() * R.transpose();
  P.block<3, 3>(3, 3) = s.p * s.p * Eigen::Matrix3d::Identity();
  P.block<3, 3>(6, 6) = s.v * s.v * Eigen::Matrix3d::Identity();
  P.block<3, 3>(9, 9) = s.bg * s.bg * Eigen::Matrix3d::Identity();
  P.block<3, 3>(12, 12) = s.ba * s.ba * Eigen::Matrix3d::Identity();
  return P;
}

InitialEstimate initial_estimate(const GroundTruth& truth, const estimator::VioOptions& options,
                                 uint64_t perturb_seed) {
  InitialEstimate init;
  init.value.q_GtoI = quat_normalize(truth.q_GtoI);
  init.value.p_IinG = truth.p_IinG;
  init.value.v_IinG = truth.v_IinG;
  init.value.bg = truth.bias_gyro;
  init.value.ba = truth.bias_accel;
  init.P0 = initial_covariance(init.value.q_GtoI, options.init_sigmas);
  if (perturb_seed == 0) return init;

  const Eigen::LLT<estimator::Matrix15d> llt(init.P0);
  if (llt.info() != Eigen::Success) {
    throw std::invalid_argument("initial_estimate: P0 from init_sigmas is not positive definite");
  }
  std::mt19937_64 rng(perturb_seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix<double, 15, 1> n;
  for (int i = 0; i < 15; ++i) n(i) = n01(rng);
  const Eigen::Matrix<double, 15, 1> d = llt.matrixL() * n;
  init.value.q_GtoI = quat_boxplus(init.value.q_GtoI, d.segment<3>(0));
  init.value.p_IinG += d.segment<3>(3);
  init.value.v_IinG += d.segment<3>(6);
  init.value.bg += d.segment<3>(9);
  init.value.ba += d.segment<3>(12);
  return init;
}

uint64_t perturb_seed_for_run(uint64_t sim_seed) {
  uint64_t z = sim_seed + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return z == 0 ? 1 : z;
}

}  // namespace eval
}  // namespace vimot

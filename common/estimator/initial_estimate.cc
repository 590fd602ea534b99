#include "common/estimator/initial_estimate.h"

#include <Eigen/Cholesky>
#include <random>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot {
namespace estimator {

InitialEstimate initial_estimate(const GroundTruth& truth, const VioOptions& options,
                                 uint64_t perturb_seed) {
  InitialEstimate init;
  init.value.q_GtoI = quat_normalize(truth.q_GtoI);
  init.value.p_IinG = truth.p_IinG;
  init.value.v_IinG = truth.v_IinG;
  init.value.bg = truth.bias_gyro;
  init.value.ba = truth.bias_accel;
  init.P0 = initial_covariance(init.value.q_GtoI, options.init_sigmas);
  if (perturb_seed == 0) return init;

  const Eigen::LLT<Matrix15d> llt(init.P0);
  if (llt.info() != Eigen::Success) {
    throw std::invalid_argument("initial_estimate: P0 from init_sigmas is not positive definite");
  }
  std::mt19937_64 rng(perturb_seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Eigen::Matrix<double, 15, 1> n;
  for (int i = 0; i < 15; ++i) n(i) = n01(rng);
  const Eigen::Matrix<double, 15, 1> d = llt.matrixL() * n;
  init.value = boxplus(init.value, d);
  return init;
}

uint64_t perturb_seed_for_run(uint64_t sim_seed) {
  uint64_t z = sim_seed + 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return z == 0 ? 1 : z;
}

}  // namespace estimator
}  // namespace vimot

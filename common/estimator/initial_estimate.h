#pragma once
// Start-from-ground-truth, shared by the offline evaluator and the `vins`
// process (init.mode: ground_truth), so both start from the same x̂0 and P0.
//
// P0 comes from VioOptions::init_sigmas exactly as
// VioEstimator::initialize(value, utime) builds it: the orientation block
// R_GtoI diag(σ_rp², σ_rp², σ_yaw²) R_GtoIᵀ (roll/pitch and yaw given in G,
// the error in I), then σ_p² I, σ_v² I, σ_bg² I, σ_ba² I.
//
// A Monte-Carlo NEES needs x̂0 − x0 ~ N(0, P0): started exactly at the truth
// with P0 > 0, the unobservable yaw and global position keep their prior
// variance without any prior error, and the NEES reads low. So
// x̂0 = x0 ⊞ L n, L Lᵀ = P0 (Cholesky), n ~ N(0, I₁₅) drawn with
// std::mt19937_64(perturb_seed) and std::normal_distribution in the error
// order [δθ δp δv δbg δba]; ⊞ is quat_boxplus for δθ (R = Exp(−δθ) R̂) and
// + for the rest. perturb_seed 0 gives exactly the truth. Deterministic (for
// one standard library: std::normal_distribution is implementation-defined).
// No LCM here.

#include <cstdint>

#include "common/estimator/vio_estimator.h"
#include "common/types/ground_truth.h"

namespace vimot {
namespace estimator {

struct InitialEstimate {
  ImuValue value;  // x̂0
  Matrix15d P0{Matrix15d::Zero()};  // [δθ δp δv δbg δba]
};

/// x̂0 and P0 from the true state (q, p, v and the true biases of `truth`).
InitialEstimate initial_estimate(const GroundTruth& truth, const VioOptions& options,
                                 uint64_t perturb_seed);

/// Perturbation seed of Monte-Carlo run with simulator seed `sim_seed`
/// (splitmix64 of it, never 0), so runs are independent and reproducible.
uint64_t perturb_seed_for_run(uint64_t sim_seed);

}  // namespace estimator
}  // namespace vimot

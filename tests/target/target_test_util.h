#pragma once
// Shared helpers of the target tests: sample states and manifold finite differences.

#include <Eigen/Core>
#include <functional>

#include "common/estimator/types.h"
#include "common/math/quat.h"
#include "common/target/target_types.h"

namespace vimot {
namespace target {
namespace test {

inline TargetValue sample_target(double scale = 1.0) {
  TargetValue x;
  x.q_RtoT = quat_normalize(Eigen::Vector4d(0.2, -0.4, 0.3, 0.8));
  x.p_TinR = Eigen::Vector3d(3.0, -1.0, 2.0);
  x.v_TinT = Eigen::Vector3d(1.2, -0.4, 0.3);
  x.w_TinT = scale * Eigen::Vector3d(0.3, -0.5, 0.7);
  return x;
}

inline estimator::ImuValue sample_imu() {
  estimator::ImuValue x;
  x.q_GtoI = quat_normalize(Eigen::Vector4d(0.1, -0.3, 0.2, 0.9));
  x.p_IinG = Eigen::Vector3d(1.0, -2.0, 0.5);
  x.v_IinG = Eigen::Vector3d(0.8, 0.3, -0.2);
  x.bg = Eigen::Vector3d(0.01, -0.02, 0.015);
  x.ba = Eigen::Vector3d(0.05, 0.1, -0.08);
  return x;
}

/// Central differences: column i = (f(+ε e_i) − f(−ε e_i)) / 2ε, where f
/// returns an error-state vector (already ⊟ the nominal output).
inline Eigen::MatrixXd central_diff(int n_in, const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
                                    double eps = 1e-6) {
  Eigen::MatrixXd J;
  for (int i = 0; i < n_in; ++i) {
    Eigen::VectorXd d = Eigen::VectorXd::Zero(n_in);
    d(i) = eps;
    const Eigen::VectorXd fp = f(d);
    const Eigen::VectorXd fm = f(-d);
    if (i == 0) J.resize(fp.size(), n_in);
    J.col(i) = (fp - fm) / (2.0 * eps);
  }
  return J;
}

/// Max |A − B| relative to max(1, max|B|).
inline double rel_err(const Eigen::MatrixXd& A, const Eigen::MatrixXd& B) {
  return (A - B).cwiseAbs().maxCoeff() / std::max(1.0, B.cwiseAbs().maxCoeff());
}

}  // namespace test
}  // namespace target
}  // namespace vimot

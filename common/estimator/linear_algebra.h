#pragma once
// Row operations on stacked linear measurement systems r = H_x x̃ + H_f f̃ + n
// with isotropic noise (orthogonal row operations keep n ~ N(0, σ² I)).

#include <Eigen/Core>
#include <vector>

namespace vimot {
namespace estimator {

/// Triangularises H_f (m × n, m >= n) with Givens rotations Gᵀ applied to
/// H_f, H_x and res alike: afterwards H_f = [U; 0] with U upper triangular
/// (n × n). The rows n..m-1 of H_x and res are then the projection onto the
/// left nullspace of the original H_f.
void givens_triangularize_inplace(Eigen::MatrixXd& H_f, Eigen::MatrixXd& H_x, Eigen::VectorXd& res);

/// Left-nullspace projection (MSCKF): with Q = [Q1 Q2] the QR basis of H_f,
/// H_x ← Q2ᵀ H_x, res ← Q2ᵀ res (m − n rows), so Q2ᵀ H_f = 0 and the
/// feature error drops out. H_f must have full column rank; it is destroyed.
void nullspace_project_inplace(Eigen::MatrixXd& H_f, Eigen::MatrixXd& H_x, Eigen::VectorXd& res);

/// Measurement compression: if H_x has more rows than columns, replaces
/// (H_x, res) by (R₁, Q₁ᵀ res) from H_x = Q₁ R₁ (thin QR), keeping at most
/// rank(H_x) ≤ cols rows. The EKF update is then the same at lower cost.
void measurement_compress_inplace(Eigen::MatrixXd& H_x, Eigen::VectorXd& res);

/// Stacks the per-feature systems (Hs[i], rs[i]), all with `cols` columns,
/// into one (H, res) and compresses it (measurement_compress_inplace).
void stack_and_compress(const std::vector<Eigen::MatrixXd>& Hs, const std::vector<Eigen::VectorXd>& rs, int cols,
                        Eigen::MatrixXd* H, Eigen::VectorXd* res);

}  // namespace estimator
}  // namespace vimot

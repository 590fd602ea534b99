#include "common/estimator/linear_algebra.h"

#include <Eigen/Jacobi>
#include <Eigen/QR>
#include <stdexcept>

namespace vimot {
namespace estimator {

void givens_triangularize_inplace(Eigen::MatrixXd& H_f, Eigen::MatrixXd& H_x, Eigen::VectorXd& res) {
  const int m = static_cast<int>(H_f.rows());
  const int n = static_cast<int>(H_f.cols());
  if (H_x.rows() != m || res.rows() != m) {
    throw std::invalid_argument("givens_triangularize_inplace: H_f, H_x and res must have the same rows");
  }
  Eigen::JacobiRotation<double> G;
  for (int c = 0; c < n; ++c) {
    // Zero column c from the bottom up, rotating neighbouring rows (r-1, r).
    for (int r = m - 1; r > c; --r) {
      if (H_f(r, c) == 0.0) continue;
      G.makeGivens(H_f(r - 1, c), H_f(r, c));
      H_f.block(r - 1, c, 2, n - c).applyOnTheLeft(0, 1, G.adjoint());
      H_x.block(r - 1, 0, 2, H_x.cols()).applyOnTheLeft(0, 1, G.adjoint());
      res.segment(r - 1, 2).applyOnTheLeft(0, 1, G.adjoint());
    }
  }
}

void nullspace_project_inplace(Eigen::MatrixXd& H_f, Eigen::MatrixXd& H_x, Eigen::VectorXd& res) {
  const int n = static_cast<int>(H_f.cols());
  const int m = static_cast<int>(H_f.rows());
  if (m <= n) {
    H_x.resize(0, H_x.cols());
    res.resize(0);
    return;
  }
  givens_triangularize_inplace(H_f, H_x, res);
  H_x = H_x.bottomRows(m - n).eval();
  res = res.tail(m - n).eval();
}

void measurement_compress_inplace(Eigen::MatrixXd& H_x, Eigen::VectorXd& res) {
  const int m = static_cast<int>(H_x.rows());
  const int n = static_cast<int>(H_x.cols());
  if (m <= n) return;
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(H_x);
  // Qᵀ res without forming Q.
  Eigen::VectorXd qtr = res;
  qtr.applyOnTheLeft(qr.householderQ().adjoint());
  const Eigen::MatrixXd R = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  // Drop trailing rows of R that are (numerically) zero: rank-deficient H_x
  // (e.g. columns of clones no measurement touches) has nothing there.
  int keep = n;
  const double scale = R.cwiseAbs().maxCoeff();
  while (keep > 0 && R.row(keep - 1).cwiseAbs().maxCoeff() <= 1e-13 * scale) --keep;
  H_x = R.topRows(keep);
  res = qtr.head(keep);
}

void stack_and_compress(const std::vector<Eigen::MatrixXd>& Hs, const std::vector<Eigen::VectorXd>& rs, int cols,
                        Eigen::MatrixXd* H, Eigen::VectorXd* res) {
  Eigen::Index rows = 0;
  for (const Eigen::VectorXd& r : rs) rows += r.size();
  H->resize(rows, cols);
  res->resize(rows);
  Eigen::Index row = 0;
  for (size_t i = 0; i < Hs.size(); ++i) {
    const Eigen::Index n = rs[i].size();
    H->middleRows(row, n) = Hs[i];
    res->segment(row, n) = rs[i];
    row += n;
  }
  measurement_compress_inplace(*H, *res);
}

}  // namespace estimator
}  // namespace vimot

#pragma once
// Chi-square quantiles for measurement gating (no Boost).
//
// chi2_quantile() inverts the regularised lower incomplete gamma function
// P(k/2, x/2) by safeguarded Newton iterations from the Wilson–Hilferty
// guess; chi2_95() serves dof 1..kChi2TableSize from a table computed once
// with it and uses Wilson–Hilferty beyond (relative error < 1e-4 there).

namespace vimot {
namespace estimator {

constexpr int kChi2TableSize = 500;

/// Regularised lower incomplete gamma P(a, x) (series / continued fraction).
double regularized_gamma_p(double a, double x);

/// Chi-square CDF with `dof` degrees of freedom.
double chi2_cdf(double x, int dof);

/// x with chi2_cdf(x, dof) = p, for 0 < p < 1 and dof >= 1 (throws
/// std::invalid_argument otherwise).
double chi2_quantile(double p, int dof);

/// Wilson–Hilferty approximation of chi2_quantile().
double chi2_quantile_wilson_hilferty(double p, int dof);

/// χ²_0.95(dof): 3.841 for 1 dof, 5.991 for 2, 18.307 for 10, 124.342 for 100.
double chi2_95(int dof);

}  // namespace estimator
}  // namespace vimot

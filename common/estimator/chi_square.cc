#include "common/estimator/chi_square.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace vimot {
namespace estimator {

namespace {

// P(a, x) by its power series, good for x < a + 1.
double gamma_p_series(double a, double x) {
  double term = 1.0 / a;
  double sum = term;
  for (int n = 1; n < 10000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Q(a, x) = 1 − P(a, x) by its continued fraction (modified Lentz), x >= a + 1.
double gamma_q_continued_fraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

double normal_quantile(double p) {
  // Acklam's rational approximation refined by one Halley step on erfc.
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  double x;
  if (p < 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else if (p > 1.0 - 0.02425) {
    const double q = std::sqrt(-2.0 * std::log(1.0 - p));
    x = -(((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  } else {
    const double q = p - 0.5;
    const double r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1.0);
  }
  const double e = 0.5 * std::erfc(-x / std::sqrt(2.0)) - p;
  const double u = e * std::sqrt(2.0 * M_PI) * std::exp(0.5 * x * x);
  return x - u / (1.0 + 0.5 * x * u);
}

}  // namespace

double regularized_gamma_p(double a, double x) {
  if (!(a > 0.0) || !(x >= 0.0)) {
    throw std::invalid_argument("regularized_gamma_p: need a > 0 and x >= 0, got a = " + std::to_string(a) +
                                ", x = " + std::to_string(x));
  }
  if (x == 0.0) return 0.0;
  if (x < a + 1.0) return gamma_p_series(a, x);
  return 1.0 - gamma_q_continued_fraction(a, x);
}

double chi2_cdf(double x, int dof) {
  if (x <= 0.0) return 0.0;
  return regularized_gamma_p(0.5 * dof, 0.5 * x);
}

double chi2_quantile_wilson_hilferty(double p, int dof) {
  const double k = dof;
  const double z = normal_quantile(p);
  const double h = 2.0 / (9.0 * k);
  const double t = 1.0 - h + z * std::sqrt(h);
  return k * t * t * t;
}

double chi2_quantile(double p, int dof) {
  if (!(p > 0.0 && p < 1.0) || dof < 1) {
    throw std::invalid_argument("chi2_quantile: need 0 < p < 1 and dof >= 1, got p = " + std::to_string(p) +
                                ", dof = " + std::to_string(dof));
  }
  const double k = dof;
  // Bracket [lo, hi] with cdf(lo) < p < cdf(hi), Newton steps kept inside.
  double lo = 0.0;
  double hi = std::max(1.0, k);
  while (chi2_cdf(hi, dof) < p) hi *= 2.0;
  double x = chi2_quantile_wilson_hilferty(p, dof);
  if (!(x > lo && x < hi)) x = 0.5 * (lo + hi);
  const double log_norm = -0.5 * k * std::log(2.0) - std::lgamma(0.5 * k);
  for (int it = 0; it < 200; ++it) {
    const double f = chi2_cdf(x, dof) - p;
    if (f < 0.0) lo = x; else hi = x;
    const double pdf = std::exp(log_norm + (0.5 * k - 1.0) * std::log(x) - 0.5 * x);
    double next = (pdf > 0.0 && std::isfinite(pdf)) ? x - f / pdf : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (std::abs(next - x) <= 1e-12 * std::max(1.0, x)) return next;
    x = next;
  }
  return x;
}

double chi2_95(int dof) {
  if (dof < 1) throw std::invalid_argument("chi2_95: dof must be >= 1, got " + std::to_string(dof));
  static const std::vector<double> table = [] {
    std::vector<double> t(kChi2TableSize + 1, 0.0);
    for (int k = 1; k <= kChi2TableSize; ++k) t[k] = chi2_quantile(0.95, k);
    return t;
  }();
  if (dof <= kChi2TableSize) return table[dof];
  return chi2_quantile_wilson_hilferty(0.95, dof);
}

}  // namespace estimator
}  // namespace vimot

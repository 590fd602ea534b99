#include <catch2/catch.hpp>

#include "common/estimator/chi_square.h"

using namespace vimot::estimator;

TEST_CASE("chi2_95 matches the tabulated quantiles", "[chi2]") {
  CHECK(chi2_95(1) == Approx(3.841459).epsilon(1e-6));
  CHECK(chi2_95(2) == Approx(5.991465).epsilon(1e-6));
  CHECK(chi2_95(3) == Approx(7.814728).epsilon(1e-6));
  CHECK(chi2_95(10) == Approx(18.307038).epsilon(1e-6));
  CHECK(chi2_95(30) == Approx(43.772972).epsilon(1e-6));
  CHECK(chi2_95(100) == Approx(124.342113).epsilon(1e-6));
  CHECK(chi2_95(500) == Approx(553.126743).epsilon(1e-6));
}

TEST_CASE("chi2_95 beyond the table uses Wilson-Hilferty", "[chi2]") {
  // χ²_0.95(1000) = 1074.679; Wilson–Hilferty is within 1e-4 there.
  CHECK(chi2_95(1000) == Approx(1074.679449).epsilon(1e-4));
  CHECK(chi2_quantile(0.95, 1000) == Approx(1074.679449).epsilon(1e-7));
  // Continuity at the table edge.
  CHECK(chi2_95(kChi2TableSize + 1) == Approx(chi2_95(kChi2TableSize)).epsilon(3e-3));
}

TEST_CASE("chi2_quantile inverts the CDF for other probabilities", "[chi2]") {
  CHECK(chi2_quantile(0.99, 1) == Approx(6.634897).epsilon(1e-6));
  CHECK(chi2_quantile(0.05, 5) == Approx(1.145476).epsilon(1e-6));
  CHECK(chi2_quantile(0.5, 2) == Approx(1.386294).epsilon(1e-6));  // 2 ln 2
  for (int k : {1, 4, 17, 250}) {
    for (double p : {0.01, 0.5, 0.95, 0.999}) CHECK(chi2_cdf(chi2_quantile(p, k), k) == Approx(p).epsilon(1e-9));
  }
  CHECK_THROWS_AS(chi2_quantile(1.0, 3), std::invalid_argument);
  CHECK_THROWS_AS(chi2_95(0), std::invalid_argument);
}

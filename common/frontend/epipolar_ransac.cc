#include "common/frontend/epipolar_ransac.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace vimot::frontend {

namespace {

// The 8-point system is solved on the 9x9 normal matrix AᵀA (only its lower
// triangle is filled and read): its smallest eigenvector is the right
// singular vector of the smallest singular value, and a 9x9 eigen-solve
// costs the same for 8 points or 300.
Eigen::Matrix3d solve_normal(const Eigen::Matrix<double, 9, 9>& AtA) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 9, 9>> eig(AtA);
  const Eigen::Matrix<double, 9, 1> f = eig.eigenvectors().col(0);
  Eigen::Matrix3d F;
  F << f(0), f(1), f(2), f(3), f(4), f(5), f(6), f(7), f(8);
  // A fundamental matrix has rank 2: zero the smallest singular value.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d s = svd.singularValues();
  s(2) = 0.0;
  return svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
}

// Hartley's normalization: moves the points' centroid to the origin and
// scales their mean distance to sqrt(2), which keeps the 8-point system
// well conditioned (without it a minimal sample's F, once forced to rank 2,
// misses its own points by pixels).
Eigen::Matrix3d hartley(const std::vector<Eigen::Vector2d>& p) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& x : p) mean += x;
  mean /= static_cast<double>(p.size());
  double spread = 0.0;
  for (const Eigen::Vector2d& x : p) spread += (x - mean).norm();
  spread /= static_cast<double>(p.size());
  const double s = spread > 0.0 ? std::sqrt(2.0) / spread : 1.0;
  Eigen::Matrix3d T;
  T << s, 0.0, -s * mean.x(), 0.0, s, -s * mean.y(), 0.0, 0.0, 1.0;
  return T;
}

Eigen::Vector2d apply(const Eigen::Matrix3d& T, const Eigen::Vector2d& x) {
  return Eigen::Vector2d(T(0, 0) * x.x() + T(0, 2), T(1, 1) * x.y() + T(1, 2));
}

// Row of the 8-point system for x_bᵀ F x_a = 0, F row-major.
Eigen::Matrix<double, 9, 1> row(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  Eigen::Matrix<double, 9, 1> r;
  r << b.x() * a.x(), b.x() * a.y(), b.x(), b.y() * a.x(), b.y() * a.y(), b.y(), a.x(), a.y(), 1.0;
  return r;
}

// Refits per improved sample: each costs one pass over the points; the
// inlier set settles within two or three.
constexpr int kMaxRefits = 3;

}  // namespace

Eigen::Matrix3d eight_point_fundamental(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  if (a.size() < 8 || a.size() != b.size()) return Eigen::Matrix3d::Zero();
  const Eigen::Matrix3d Ta = hartley(a), Tb = hartley(b);
  Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Matrix<double, 9, 1> r = row(apply(Ta, a[i]), apply(Tb, b[i]));
    AtA.selfadjointView<Eigen::Lower>().rankUpdate(r);
  }
  return Tb.transpose() * solve_normal(AtA) * Ta;
}

double sampson_distance_squared(const Eigen::Matrix3d& F, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector3d ha(a.x(), a.y(), 1.0), hb(b.x(), b.y(), 1.0);
  const Eigen::Vector3d Fa = F * ha;
  const Eigen::Vector3d Ftb = F.transpose() * hb;
  const double denom = Fa.x() * Fa.x() + Fa.y() * Fa.y() + Ftb.x() * Ftb.x() + Ftb.y() * Ftb.y();
  if (!(denom > 0.0)) return std::numeric_limits<double>::infinity();
  const double e = hb.dot(Fa);
  return e * e / denom;
}

EpipolarRansac::EpipolarRansac(const RansacOptions& options) : options_(options), rng_(options.seed) {
  options_.validate();
}

std::vector<bool> EpipolarRansac::inliers(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b,
                                          double focal_px) {
  if (a.size() != b.size()) {
    throw std::invalid_argument("EpipolarRansac: " + std::to_string(a.size()) + " points against " +
                                std::to_string(b.size()));
  }
  const std::size_t n = a.size();
  std::vector<bool> best(n, true);
  if (n < static_cast<std::size_t>(options_.min_points)) return best;

  const double threshold = options_.threshold_px / focal_px;
  const double threshold2 = threshold * threshold;
  auto count_inliers = [&](const Eigen::Matrix3d& F, std::vector<bool>* flags) {
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const bool in = sampson_distance_squared(F, a[i], b[i]) < threshold2;
      (*flags)[i] = in;
      count += in ? 1 : 0;
    }
    return count;
  };

  const Eigen::Matrix3d Ta = hartley(a), Tb = hartley(b);
  std::vector<Eigen::Matrix<double, 9, 1>> rows(n);
  for (std::size_t i = 0; i < n; ++i) rows[i] = row(apply(Ta, a[i]), apply(Tb, b[i]));

  int best_count = -1;
  std::vector<bool> flags(n);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  int needed = options_.max_iterations;
  for (int iter = 0; iter < needed; ++iter) {
    // 8 distinct indices.
    std::size_t sample[8];
    for (int k = 0; k < 8; ++k) {
      bool fresh = false;
      while (!fresh) {
        sample[k] = pick(rng_);
        fresh = true;
        for (int j = 0; j < k; ++j) fresh = fresh && sample[j] != sample[k];
      }
    }
    Eigen::Matrix<double, 9, 9> AtA = Eigen::Matrix<double, 9, 9>::Zero();
    for (const std::size_t i : sample) AtA.selfadjointView<Eigen::Lower>().rankUpdate(rows[i]);
    int count = count_inliers(Tb.transpose() * solve_normal(AtA) * Ta, &flags);
    if (count <= best_count) continue;
    // Local optimisation (LO-RANSAC): refit on the inliers while that gains
    // inliers. A minimal sample's model is only roughly right; its refit on
    // all its inliers usually finds the rest, so far fewer samples suffice.
    for (int refit = 0; refit < kMaxRefits && count >= 8; ++refit) {
      Eigen::Matrix<double, 9, 9> M = Eigen::Matrix<double, 9, 9>::Zero();
      for (std::size_t i = 0; i < n; ++i) {
        if (flags[i]) M.selfadjointView<Eigen::Lower>().rankUpdate(rows[i]);
      }
      std::vector<bool> refit_flags(n);
      const int refit_count = count_inliers(Tb.transpose() * solve_normal(M) * Ta, &refit_flags);
      if (refit_count <= count) break;
      count = refit_count;
      flags.swap(refit_flags);
    }
    if (count > best_count) {
      best_count = count;
      best = flags;
      // Iterations for `confidence` of having drawn one all-inlier sample.
      const double w = static_cast<double>(count) / static_cast<double>(n);
      const double p_good = std::pow(w, 8);
      if (p_good >= 1.0 - 1e-12) {
        needed = iter + 1;
      } else if (p_good > 0.0) {
        // In double: for a poor model k exceeds any int.
        const double k = std::log(1.0 - options_.confidence) / std::log(1.0 - p_good);
        needed = k < options_.max_iterations ? static_cast<int>(std::ceil(k)) : options_.max_iterations;
      }
    }
  }
  return best;
}

}  // namespace vimot::frontend

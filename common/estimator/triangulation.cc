#include "common/estimator/triangulation.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace vimot {
namespace estimator {

namespace {

struct RelObs {
  Eigen::Matrix3d R_AtoC;
  Eigen::Vector3d p_AinC;
  Eigen::Vector2d uv;
};

// Camera pose in G: R_GtoC, p_CinG.
void camera_pose(const ClonePose& clone, const CameraInfo& cam, Eigen::Matrix3d* R_GtoC, Eigen::Vector3d* p_CinG) {
  *R_GtoC = cam.R_ItoC * clone.R_GtoI;
  *p_CinG = clone.p_IinG - clone.R_GtoI.transpose() * cam.R_ItoC.transpose() * cam.p_IinC;
}

double reprojection_cost(const std::vector<RelObs>& obs, const Eigen::Vector3d& x) {
  double cost = 0.0;
  const Eigen::Vector3d ab1(x(0), x(1), 1.0);
  for (const auto& o : obs) {
    const Eigen::Vector3d h = o.R_AtoC * ab1 + x(2) * o.p_AinC;
    if (h.z() <= 0.0) return std::numeric_limits<double>::infinity();
    cost += (o.uv - h.head<2>() / h.z()).squaredNorm();
  }
  return cost;
}

}  // namespace

FeatureTriangulator::FeatureTriangulator(const TriangulationOptions& options, const std::vector<CameraInfo>& cameras)
    : options_(options), cameras_(cameras) {
  if (!(options_.min_depth > 0.0) || !(options_.max_depth > options_.min_depth) || !(options_.max_condition > 1.0) ||
      options_.max_iterations < 0) {
    throw std::invalid_argument("TriangulationOptions: need 0 < min_depth < max_depth, max_condition > 1, "
                                "max_iterations >= 0");
  }
}

bool FeatureTriangulator::triangulate(Feature& feat, const ClonePoses& clones) const {
  // Anchor: the camera with the earliest observation.
  int anchor_cam = -1;
  int64_t anchor_t = std::numeric_limits<int64_t>::max();
  for (const auto& kv : feat.obs) {
    if (kv.first < 0 || kv.first >= static_cast<int>(cameras_.size())) continue;
    for (const auto& o : kv.second) {
      if (clones.count(o.utime) && o.utime < anchor_t) {
        anchor_t = o.utime;
        anchor_cam = kv.first;
      }
    }
  }
  if (anchor_cam < 0) return false;
  Eigen::Matrix3d R_GtoA;
  Eigen::Vector3d p_AinG;
  camera_pose(clones.at(anchor_t), cameras_[anchor_cam], &R_GtoA, &p_AinG);

  std::vector<RelObs> rel;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& kv : feat.obs) {
    if (kv.first < 0 || kv.first >= static_cast<int>(cameras_.size())) continue;
    for (const auto& o : kv.second) {
      const auto it = clones.find(o.utime);
      if (it == clones.end()) continue;
      Eigen::Matrix3d R_GtoC;
      Eigen::Vector3d p_CinG;
      camera_pose(it->second, cameras_[kv.first], &R_GtoC, &p_CinG);
      const Eigen::Matrix3d R_CtoA = R_GtoA * R_GtoC.transpose();
      const Eigen::Vector3d p_CinA = R_GtoA * (p_CinG - p_AinG);
      const Eigen::Vector3d bearing = (R_CtoA * Eigen::Vector3d(o.uv.x(), o.uv.y(), 1.0)).normalized();
      const Eigen::Matrix3d N = Eigen::Matrix3d::Identity() - bearing * bearing.transpose();
      A += N;
      b += N * p_CinA;
      RelObs r;
      r.R_AtoC = R_CtoA.transpose();
      r.p_AinC = -r.R_AtoC * p_CinA;
      r.uv = o.uv;
      rel.push_back(r);
    }
  }
  if (rel.size() < 2) return false;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sv = svd.singularValues();
  if (!(sv(2) > 0.0) || sv(0) / sv(2) > options_.max_condition) return false;
  const Eigen::Vector3d p_lin = svd.solve(b);
  if (!(p_lin.z() >= options_.min_depth && p_lin.z() <= options_.max_depth)) return false;

  // Levenberg–Marquardt in inverse depth.
  Eigen::Vector3d x(p_lin.x() / p_lin.z(), p_lin.y() / p_lin.z(), 1.0 / p_lin.z());
  double cost = reprojection_cost(rel, x);
  double lambda = 1e-3;
  for (int it = 0; it < options_.max_iterations && std::isfinite(cost); ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    const Eigen::Vector3d ab1(x(0), x(1), 1.0);
    for (const auto& o : rel) {
      const Eigen::Vector3d h = o.R_AtoC * ab1 + x(2) * o.p_AinC;
      Eigen::Matrix3d dh;
      dh << o.R_AtoC.col(0), o.R_AtoC.col(1), o.p_AinC;
      const Eigen::Matrix<double, 2, 3> J = project_jacobian(h) * dh;
      const Eigen::Vector2d r = o.uv - h.head<2>() / h.z();
      H += J.transpose() * J;
      g += J.transpose() * r;
    }
    bool improved = false;
    for (int tries = 0; tries < 10 && !improved; ++tries) {
      Eigen::Matrix3d Hd = H;
      Hd.diagonal() *= (1.0 + lambda);
      const Eigen::Vector3d dx = Hd.ldlt().solve(g);
      const Eigen::Vector3d x_new = x + dx;
      const double c_new = reprojection_cost(rel, x_new);
      if (c_new < cost) {
        const double step = dx.norm();
        x = x_new;
        cost = c_new;
        lambda = std::max(lambda / 10.0, 1e-10);
        improved = true;
        if (step < 1e-10 * std::max(1.0, x.norm())) it = options_.max_iterations;
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  if (!std::isfinite(cost) || !(x(2) > 0.0)) return false;
  const double depth = 1.0 / x(2);
  if (!(depth >= options_.min_depth && depth <= options_.max_depth)) return false;
  // In front of every observing camera.
  const Eigen::Vector3d p_FinA(x(0) * depth, x(1) * depth, depth);
  for (const auto& o : rel) {
    if ((o.R_AtoC * p_FinA + o.p_AinC).z() < options_.min_depth) return false;
  }
  feat.anchor_camera = anchor_cam;
  feat.anchor_utime = anchor_t;
  feat.p_FinA = p_FinA;
  feat.p_FinG = p_AinG + R_GtoA.transpose() * p_FinA;
  return true;
}

}  // namespace estimator
}  // namespace vimot

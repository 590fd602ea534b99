#include "common/estimator/updater_msckf.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>

#include "common/estimator/chi_square.h"
#include "common/estimator/linear_algebra.h"
#include "common/estimator/state_helper.h"

namespace vimot {
namespace estimator {

ClonePoses clone_poses(const State& state) {
  ClonePoses poses;
  for (const auto& kv : state.clones()) poses[kv.first] = ClonePose{kv.second->Rot(), kv.second->pos()};
  return poses;
}

UpdaterMsckf::UpdaterMsckf(const MsckfOptions& options, const TriangulationOptions& triangulation,
                           const std::vector<CameraInfo>& cameras)
    : options_(options), cameras_(cameras), triangulator_(triangulation, cameras) {
  if (!(options_.chi2_multiplier > 0.0) || options_.max_features_per_update < 0 || options_.min_clone_times < 2) {
    throw std::invalid_argument("MsckfOptions: need chi2_multiplier > 0, max_features_per_update >= 0, "
                                "min_clone_times >= 2");
  }
}

bool UpdaterMsckf::feature_system(const State& state, const Feature& feat, ColumnLayout& layout,
                                  Eigen::MatrixXd* H_x, Eigen::MatrixXd* H_f, Eigen::VectorXd* res) const {
  const int m = feat.num_obs();
  H_x->setZero(2 * m, layout.total());
  H_f->setZero(2 * m, 3);
  res->setZero(2 * m);
  const bool fej = state.options().use_fej;
  int row = 0;
  for (const auto& kv : feat.obs) {
    if (kv.first < 0 || kv.first >= static_cast<int>(cameras_.size())) return false;
    const CameraInfo& cam = cameras_[kv.first];
    for (const auto& o : kv.second) {
      const auto clone = state.clone_at(o.utime);
      if (!clone || !layout.has(clone)) return false;
      const Eigen::Vector2d z_hat = global_point_measurement(clone->Rot(), clone->pos(), feat.p_FinG, cam, nullptr,
                                                             nullptr);
      Eigen::Matrix<double, 2, 6> H_pose;
      Eigen::Matrix<double, 2, 3> H_point;
      global_point_measurement(fej ? clone->Rot_fej() : clone->Rot(), fej ? clone->pos_fej() : clone->pos(),
                               feat.p_FinG, cam, &H_pose, &H_point);
      const Eigen::Matrix2d W = cam.whitening(o.uv);
      H_x->block<2, 6>(row, layout.col(clone)) = W * H_pose;
      H_f->block<2, 3>(row, 0) = W * H_point;
      res->segment<2>(row) = W * (o.uv - z_hat);
      row += 2;
    }
  }
  return true;
}

void UpdaterMsckf::update(State& state, std::vector<std::shared_ptr<Feature>> features, UpdateStats* stats,
                          std::vector<std::shared_ptr<Feature>>* deferred) const {
  if (features.empty() || state.clones().size() < 2) return;
  stats->msckf_candidates += static_cast<int>(features.size());

  // Observations only at clone times; tracks long enough.
  std::set<int64_t> clone_times;
  for (const auto& kv : state.clones()) clone_times.insert(kv.first);
  std::vector<std::shared_ptr<Feature>> usable;
  for (auto& f : features) {
    f->keep_times(clone_times);
    if (static_cast<int>(f->times().size()) >= options_.min_clone_times) {
      usable.push_back(f);
    } else {
      ++stats->msckf_rejected_short;
    }
  }
  // Longest tracks first (ties by id, for determinism).
  std::sort(usable.begin(), usable.end(), [](const std::shared_ptr<Feature>& a, const std::shared_ptr<Feature>& b) {
    const int na = a->num_obs(), nb = b->num_obs();
    return na != nb ? na > nb : a->feature_id < b->feature_id;
  });
  if (static_cast<int>(usable.size()) > options_.max_features_per_update) {
    stats->msckf_dropped_over_max += static_cast<int>(usable.size()) - options_.max_features_per_update;
    if (deferred) deferred->insert(deferred->end(), usable.begin() + options_.max_features_per_update, usable.end());
    usable.resize(options_.max_features_per_update);
  }
  if (usable.empty()) return;

  const ClonePoses poses = clone_poses(state);
  ColumnLayout layout;
  for (const auto& kv : state.clones()) layout.col(kv.second);
  const Eigen::MatrixXd P_xx = StateHelper::marginal_covariance(state, layout.order());

  std::vector<Eigen::MatrixXd> Hs;
  std::vector<Eigen::VectorXd> rs;
  int total_rows = 0;
  for (auto& f : usable) {
    if (!triangulator_.triangulate(*f, poses)) {
      ++stats->msckf_rejected_triangulation;
      continue;
    }
    Eigen::MatrixXd H_x, H_f;
    Eigen::VectorXd r;
    if (!feature_system(state, *f, layout, &H_x, &H_f, &r)) {
      ++stats->msckf_rejected_triangulation;
      continue;
    }
    nullspace_project_inplace(H_f, H_x, r);
    if (r.size() == 0) {
      ++stats->msckf_rejected_triangulation;
      continue;
    }
    Eigen::MatrixXd S = H_x * P_xx * H_x.transpose();
    S.diagonal().array() += 1.0;
    const double chi2 = r.dot(S.llt().solve(r));
    if (!(chi2 < options_.chi2_multiplier * chi2_95(static_cast<int>(r.size())))) {
      ++stats->msckf_rejected_chi2;
      continue;
    }
    ++stats->msckf_used;
    total_rows += static_cast<int>(r.size());
    Hs.push_back(std::move(H_x));
    rs.push_back(std::move(r));
  }
  if (total_rows == 0) return;
  stats->msckf_rows += total_rows;
  Eigen::MatrixXd H;
  Eigen::VectorXd r;
  stack_and_compress(Hs, rs, layout.total(), &H, &r);
  StateHelper::ekf_update(state, layout.order(), H, r, Eigen::MatrixXd::Identity(r.size(), r.size()));
}

}  // namespace estimator
}  // namespace vimot

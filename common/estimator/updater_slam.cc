#include "common/estimator/updater_slam.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <stdexcept>

#include "common/estimator/chi_square.h"
#include "common/estimator/state_helper.h"
#include "common/estimator/updater_msckf.h"

namespace vimot {
namespace estimator {

bool landmark_measurement(const State& state, const Landmark& landmark, const PoseJPL& clone, int camera_id,
                          const std::vector<CameraInfo>& cameras, LandmarkMeasurement* out) {
  if (camera_id < 0 || camera_id >= static_cast<int>(cameras.size())) return false;
  const CameraInfo& cam = cameras[camera_id];
  const bool fej = state.options().use_fej;
  Eigen::Vector3d p_FinG, p_FinG_lin;
  Eigen::Matrix3d dpf_dl = Eigen::Matrix3d::Identity();
  Eigen::Matrix<double, 3, 6> dpf_da = Eigen::Matrix<double, 3, 6>::Zero();
  out->anchor = nullptr;
  if (landmark.representation() == LandmarkRepresentation::kGlobalXyz) {
    p_FinG = landmark.value();
    p_FinG_lin = fej ? Eigen::Vector3d(landmark.fej()) : p_FinG;
  } else {
    const auto anchor = state.clone_at(landmark.anchor_utime);
    if (!anchor || landmark.anchor_camera < 0 || landmark.anchor_camera >= static_cast<int>(cameras.size())) {
      return false;
    }
    const CameraInfo& acam = cameras[landmark.anchor_camera];
    p_FinG = anchored_to_global(landmark.value(), anchor->Rot(), anchor->pos(), acam, nullptr, nullptr);
    p_FinG_lin = fej ? anchored_to_global(landmark.fej(), anchor->Rot_fej(), anchor->pos_fej(), acam, &dpf_dl, &dpf_da)
                     : anchored_to_global(landmark.value(), anchor->Rot(), anchor->pos(), acam, &dpf_dl, &dpf_da);
    out->anchor = anchor;
  }
  if (point_in_camera(clone.Rot(), clone.pos(), p_FinG, cam).z() <= 0.0) return false;
  out->z_hat = global_point_measurement(clone.Rot(), clone.pos(), p_FinG, cam, nullptr, nullptr);
  Eigen::Matrix<double, 2, 3> H_f;
  global_point_measurement(fej ? clone.Rot_fej() : clone.Rot(), fej ? clone.pos_fej() : clone.pos(), p_FinG_lin,
                           cam, &out->H_clone, &H_f);
  out->H_landmark = H_f * dpf_dl;
  out->H_anchor = H_f * dpf_da;
  return true;
}

UpdaterSlam::UpdaterSlam(const SlamOptions& options, const TriangulationOptions& triangulation,
                         const std::vector<CameraInfo>& cameras)
    : options_(options), cameras_(cameras), triangulator_(triangulation, cameras) {
  if (!(options_.chi2_multiplier > 0.0) || options_.max_init_per_frame < 0 || options_.max_chi2_failures < 1) {
    throw std::invalid_argument("SlamOptions: need chi2_multiplier > 0, max_init_per_frame >= 0 and "
                                "max_chi2_failures >= 1");
  }
}

void UpdaterSlam::update(State& state, const std::map<int64_t, Feature>& current, UpdateStats* stats) const {
  if (current.empty()) return;
  ColumnLayout layout;
  struct Block {
    std::vector<TypePtr> vars;
    Eigen::MatrixXd H;  // columns over vars
    Eigen::VectorXd r;
  };
  std::vector<Block> accepted;
  for (const auto& kv : current) {
    const auto it = state.slam_features().find(kv.first);
    if (it == state.slam_features().end()) continue;
    const auto& landmark = it->second;
    ColumnLayout local;
    local.col(landmark);
    const int m = kv.second.num_obs();
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2 * m, 3 + 12);
    Eigen::VectorXd r(2 * m);
    int row = 0;
    bool ok = true;
    for (const auto& cobs : kv.second.obs) {
      for (const auto& o : cobs.second) {
        const auto clone = state.clone_at(o.utime);
        LandmarkMeasurement lm;
        if (!clone || !landmark_measurement(state, *landmark, *clone, cobs.first, cameras_, &lm)) {
          ok = false;
          break;
        }
        const Eigen::Matrix2d W = cameras_[cobs.first].whitening(o.uv);
        H.block<2, 3>(row, local.col(landmark)) += W * lm.H_landmark;
        H.block<2, 6>(row, local.col(clone)) += W * lm.H_clone;
        if (lm.anchor) H.block<2, 6>(row, local.col(lm.anchor)) += W * lm.H_anchor;
        r.segment<2>(row) = W * (o.uv - lm.z_hat);
        row += 2;
      }
      if (!ok) break;
    }
    if (!ok || row == 0) {
      landmark->should_marginalize = true;
      continue;
    }
    H.conservativeResize(row, local.total());
    r.conservativeResize(row);
    const Eigen::MatrixXd P = StateHelper::marginal_covariance(state, local.order());
    Eigen::MatrixXd S = H * P * H.transpose();
    S.diagonal().array() += 1.0;
    const double chi2 = r.dot(S.llt().solve(r));
    if (!(chi2 < options_.chi2_multiplier * chi2_95(static_cast<int>(r.size())))) {
      ++stats->slam_rejected_chi2;
      ++landmark->chi2_failures;
      if (landmark->chi2_failures >= options_.max_chi2_failures) landmark->should_marginalize = true;
      continue;
    }
    landmark->chi2_failures = 0;
    ++stats->slam_updated;
    accepted.push_back(Block{local.order(), std::move(H), std::move(r)});
  }
  if (accepted.empty()) return;
  int rows = 0;
  for (const auto& b : accepted) {
    for (const auto& v : b.vars) layout.col(v);
    rows += static_cast<int>(b.r.size());
  }
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(rows, layout.total());
  Eigen::VectorXd r(rows);
  int row = 0;
  for (const auto& b : accepted) {
    const int n = static_cast<int>(b.r.size());
    int c = 0;
    for (const auto& v : b.vars) {
      H.block(row, layout.col(v), n, v->size()) = b.H.middleCols(c, v->size());
      c += v->size();
    }
    r.segment(row, n) = b.r;
    row += n;
  }
  StateHelper::ekf_update(state, layout.order(), H, r, Eigen::MatrixXd::Identity(rows, rows));
}

int UpdaterSlam::change_anchors(State& state, int64_t marg_utime) const {
  if (state.clones().empty()) return 0;
  const int64_t t_new = state.clones().rbegin()->first;
  if (t_new == marg_utime) return 0;
  const auto B = state.clone_at(t_new);
  const bool fej = state.options().use_fej;
  int count = 0;
  for (const auto& kv : state.slam_features()) {
    const auto& lm = kv.second;
    if (lm->representation() != LandmarkRepresentation::kAnchoredInverseDepth || lm->should_marginalize ||
        lm->anchor_utime != marg_utime) {
      continue;
    }
    const auto A = state.clone_at(lm->anchor_utime);
    if (!A || lm->anchor_camera < 0 || lm->anchor_camera >= static_cast<int>(cameras_.size())) {
      lm->should_marginalize = true;
      continue;
    }
    const CameraInfo& cam = cameras_[lm->anchor_camera];
    Eigen::Matrix<double, 3, 15> J;
    const Eigen::Vector3d value = change_anchor(lm->value(), A->Rot(), A->pos(), cam, B->Rot(), B->pos(), cam,
                                                fej ? nullptr : &J);
    const Eigen::Vector3d value_fej = change_anchor(lm->fej(), A->Rot_fej(), A->pos_fej(), cam, B->Rot_fej(),
                                                    B->pos_fej(), cam, fej ? &J : nullptr);
    if (!(value(2) > 0.0) || !(value_fej(2) > 0.0) || !value.allFinite() || !value_fej.allFinite() ||
        !J.allFinite()) {
      lm->should_marginalize = true;
      continue;
    }
    StateHelper::transform_variable(state, lm, {lm, A, B}, J);
    lm->set_value(value);
    lm->set_fej(value_fej);
    lm->anchor_utime = t_new;
    ++count;
  }
  return count;
}

std::vector<int64_t> UpdaterSlam::delayed_initialize(State& state, std::vector<std::shared_ptr<Feature>> features,
                                                     UpdateStats* stats) const {
  std::vector<int64_t> added;
  if (features.empty()) return added;
  const int free_slots = state.options().max_slam - static_cast<int>(state.slam_features().size());
  const int budget = std::min(free_slots, options_.max_init_per_frame);
  if (budget <= 0) return added;
  // Longest tracks first.
  std::sort(features.begin(), features.end(), [](const std::shared_ptr<Feature>& a, const std::shared_ptr<Feature>& b) {
    const int na = a->num_obs(), nb = b->num_obs();
    return na != nb ? na > nb : a->feature_id < b->feature_id;
  });
  std::set<int64_t> clone_times;
  for (const auto& kv : state.clones()) clone_times.insert(kv.first);
  const ClonePoses poses = clone_poses(state);
  const auto representation = state.options().slam_representation;
  const int64_t t_now = state.clones().rbegin()->first;

  for (auto& f : features) {
    if (static_cast<int>(added.size()) >= budget) break;
    f->keep_times(clone_times);
    if (f->times().size() < 2 || !triangulator_.triangulate(*f, poses)) {
      ++stats->slam_init_rejected;
      continue;
    }
    auto landmark = std::make_shared<Landmark>(f->feature_id, representation);
    std::shared_ptr<PoseJPL> anchor;
    const CameraInfo* acam = nullptr;
    if (representation == LandmarkRepresentation::kGlobalXyz) {
      landmark->set_value(f->p_FinG);
      landmark->set_fej(f->p_FinG);
    } else {
      // Anchor: the newest clone, in the lowest camera that sees the feature now.
      int cam_now = -1;
      for (const auto& kv : f->obs) {
        if (!kv.second.empty() && kv.second.back().utime == t_now) {
          cam_now = kv.first;
          break;
        }
      }
      if (cam_now < 0 || cam_now >= static_cast<int>(cameras_.size())) {
        ++stats->slam_init_rejected;
        continue;
      }
      anchor = state.clone_at(t_now);
      acam = &cameras_[cam_now];
      landmark->anchor_utime = t_now;
      landmark->anchor_camera = cam_now;
      landmark->set_value(global_to_anchored(f->p_FinG, anchor->Rot(), anchor->pos(), *acam));
      landmark->set_fej(global_to_anchored(f->p_FinG, anchor->Rot_fej(), anchor->pos_fej(), *acam));
    }
    // Whitened system over the clones (and anchor) and the landmark.
    ColumnLayout layout;
    for (const auto& kv : state.clones()) layout.col(kv.second);
    const int m = f->num_obs();
    Eigen::MatrixXd H_R = Eigen::MatrixXd::Zero(2 * m, layout.total());
    Eigen::MatrixXd H_L = Eigen::MatrixXd::Zero(2 * m, 3);
    Eigen::VectorXd r(2 * m);
    int row = 0;
    bool ok = true;
    for (const auto& cobs : f->obs) {
      if (cobs.first < 0 || cobs.first >= static_cast<int>(cameras_.size())) {
        ok = false;
        break;
      }
      for (const auto& o : cobs.second) {
        const auto clone = state.clone_at(o.utime);
        LandmarkMeasurement lm;
        // The landmark is not in the state yet: evaluate with its values.
        if (!clone || !landmark_measurement(state, *landmark, *clone, cobs.first, cameras_, &lm)) {
          ok = false;
          break;
        }
        const Eigen::Matrix2d W = cameras_[cobs.first].whitening(o.uv);
        H_R.block<2, 6>(row, layout.col(clone)) += W * lm.H_clone;
        if (lm.anchor) H_R.block<2, 6>(row, layout.col(lm.anchor)) += W * lm.H_anchor;
        H_L.block<2, 3>(row, 0) = W * lm.H_landmark;
        r.segment<2>(row) = W * (o.uv - lm.z_hat);
        row += 2;
      }
      if (!ok) break;
    }
    if (!ok) {
      ++stats->slam_init_rejected;
      continue;
    }
    if (!StateHelper::initialize(state, landmark, layout.order(), H_R, H_L, r, 1.0, options_.chi2_multiplier)) {
      ++stats->slam_init_rejected;
      continue;
    }
    StateHelper::register_slam_feature(state, landmark);
    ++stats->slam_initialized;
    added.push_back(f->feature_id);
  }
  return added;
}

}  // namespace estimator
}  // namespace vimot

#include "common/target/target_filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <set>
#include <stdexcept>

#include "common/estimator/chi_square.h"
#include "common/estimator/linear_algebra.h"
#include "common/estimator/measurement_model.h"
#include "common/estimator/state_helper.h"
#include "common/estimator/updater_common.h"
#include "common/math/quat.h"
#include "common/target/target_conversion.h"
#include "common/target/target_measurement.h"
#include "common/time/utime.h"

namespace vimot {
namespace target {

using estimator::PoseJPL;
using estimator::State;
using estimator::StateHelper;
using estimator::TypePtr;

// ---------------------------------------------------------------- TargetState
TargetState::TargetState()
    : Type(12), pose_(std::make_shared<PoseJPL>()), v_(std::make_shared<estimator::Vec>(3)),
      w_(std::make_shared<estimator::Vec>(3)) {
  const Eigen::VectorXd x = TargetValue().to_vector();
  set_value(x);
  set_fej(x);
}

void TargetState::set_local_id(int new_id) {
  id_ = new_id;
  pose_->set_local_id(new_id);
  v_->set_local_id(new_id < 0 ? -1 : new_id + 6);
  w_->set_local_id(new_id < 0 ? -1 : new_id + 9);
}

void TargetState::update(const Eigen::VectorXd& dx) {
  if (dx.size() != 12) throw std::invalid_argument("TargetState::update: expected 12, got " + std::to_string(dx.size()));
  Eigen::VectorXd x = value_;
  x.head<4>() = quat_boxplus(Eigen::Vector4d(value_.head<4>()), Eigen::Vector3d(dx.head<3>()));
  x.segment<3>(4) += dx.segment<3>(3);
  x.segment<3>(7) += dx.segment<3>(6);
  x.segment<3>(10) += dx.segment<3>(9);
  set_value(x);
}

void TargetState::set_value(const Eigen::VectorXd& value) {
  if (value.size() != 13) throw std::invalid_argument("TargetState::set_value: expected 13");
  pose_->set_value(value.head<7>());
  v_->set_value(value.segment<3>(7));
  w_->set_value(value.segment<3>(10));
  value_.resize(13);
  value_ << pose_->value(), v_->value(), w_->value();
}

void TargetState::set_fej(const Eigen::VectorXd& fej) {
  if (fej.size() != 13) throw std::invalid_argument("TargetState::set_fej: expected 13");
  pose_->set_fej(fej.head<7>());
  v_->set_fej(fej.segment<3>(7));
  w_->set_fej(fej.segment<3>(10));
  fej_.resize(13);
  fej_ << pose_->fej(), v_->fej(), w_->fej();
}

std::shared_ptr<estimator::Type> TargetState::clone_type() const {
  auto c = std::make_shared<TargetState>();
  c->set_value(value_);
  c->set_fej(fej_);
  return c;
}

bool TargetState::contains(const estimator::Type* other) const {
  return other == this || pose_->contains(other) || other == v_.get() || other == w_.get();
}

TargetValue TargetState::get() const { return TargetValue::from_vector(value_); }

// ---------------------------------------------------------------- options
const char* to_string(TargetUpdateMode mode) {
  switch (mode) {
    case TargetUpdateMode::kOff: return "off";
    case TargetUpdateMode::kEkf: return "ekf";
    case TargetUpdateMode::kSkf: return "skf";
  }
  return "unknown";
}

TargetNoise TargetFilterOptions::noise() const {
  return planar ? TargetNoise::planar(sigma_t, sigma_t) : TargetNoise::isotropic(sigma_t, sigma_t);
}

// ---------------------------------------------------------------- filter
TargetFilter::TargetFilter(estimator::VioEstimator& estimator, const TargetFilterOptions& options)
    : estimator_(estimator), options_(options), noise_(options.noise()) {
  if (!noise_.valid() || !(options_.sigma_t >= 0.0)) throw std::invalid_argument("TargetFilterOptions: bad sigma_t");
  if (!(options_.chi2_multiplier > 0.0)) throw std::invalid_argument("TargetFilterOptions: chi2_multiplier must be > 0");
  if (options_.min_clone_times < 2) throw std::invalid_argument("TargetFilterOptions: min_clone_times must be >= 2");
  estimator_.set_extension(this);
}

TargetFilter::~TargetFilter() {
  if (estimator_.extension() == this) estimator_.set_extension(nullptr);
}

void TargetFilter::reset() {
  target_.reset();
  clones_.clear();
  pending_.reset();
  tracks_.clear();
}

TargetValue TargetFilter::value() const { return target_ ? target_->get() : TargetValue(); }

Matrix12d TargetFilter::covariance() const {
  if (!target_) return Matrix12d::Zero();
  return estimator_.state().cov().block<12, 12>(target_->id(), target_->id());
}

Eigen::Vector3d TargetFilter::p_TinI(Eigen::Matrix3d* cov) const {
  if (!target_) return Eigen::Vector3d::Zero();
  const State& st = estimator_.state();
  const TargetValue x = target_->get();
  if (options_.representation == TargetRepresentation::kLocal) {
    if (cov) *cov = st.cov().block<3, 3>(target_->id() + 3, target_->id() + 3);
    return x.p_TinR;
  }
  const estimator::ImuValue imu = st.imu()->get();
  const Eigen::Matrix3d R = quat_to_rot(imu.q_GtoI);
  const Eigen::Vector3d d = x.p_TinR - imu.p_IinG;
  if (cov) {
    // p_TinI = R_GtoI d, R_GtoI = Exp(−δθ) R̂: ∂/∂δθ_I = [(R̂ d)×], ∂/∂δp_I = −R̂, ∂/∂δp_T = R̂.
    Eigen::Matrix<double, 3, 9> J;
    J << skew(R * d), -R, R;
    const Eigen::MatrixXd P =
        StateHelper::marginal_covariance(st, {st.imu()->pose()->q(), st.imu()->pose()->p(), target_->pose()->p()});
    *cov = J * P * J.transpose();
  }
  return R * d;
}

bool TargetFilter::propagate_jointly(const State& state, const estimator::ImuValue& x0, const estimator::ImuValue& x1,
                                     const estimator::Matrix15d& Phi_II, const estimator::Matrix15d& Q_II, int64_t t0,
                                     int64_t t1, std::vector<TypePtr>* order, Eigen::MatrixXd* Phi,
                                     Eigen::MatrixXd* Q) {
  if (!target_) return false;
  const double dt = utime_to_seconds(t1 - t0);
  const TargetStep step =
      propagate_target(options_.representation, target_->get(), x0, x1, Phi_II, Q_II, dt, noise_);
  Eigen::Matrix<double, 27, 27> F, Qd;
  joint_transition(Phi_II, Q_II, step, &F, &Qd);
  *order = {state.imu(), target_};
  *Phi = F;
  *Q = Qd;
  pending_ = step.x;
  return true;
}

void TargetFilter::commit_propagation(State&) {
  if (!target_ || !pending_) return;
  const Eigen::VectorXd v = pending_->to_vector();
  target_->set_value(v);
  target_->set_fej(v);
  pending_.reset();
}

void TargetFilter::on_clone_added(State& state, int64_t utime) {
  if (!target_) return;
  clones_[utime] = std::dynamic_pointer_cast<PoseJPL>(StateHelper::clone(state, target_->pose()));
}

void TargetFilter::on_clone_marginalized(State& state, int64_t utime) {
  const auto it = clones_.find(utime);
  if (it != clones_.end()) {
    StateHelper::marginalize(state, it->second);
    clones_.erase(it);
  }
  tracks_.clean_older_than(utime + 1);
}

bool TargetFilter::initialize_from_truth(State& state, int64_t utime) {
  if (!truth_ || truth_->utime != utime || !truth_->has_target) return false;
  TargetValue global;
  global.q_RtoT = truth_->q_GtoT;
  global.p_TinR = truth_->p_TinG;
  global.v_TinT = truth_->v_TinT;
  global.w_TinT = truth_->w_TinT;
  TargetValue x = global;
  if (options_.representation == TargetRepresentation::kLocal) {
    // The true relative pose (robot-centric truth).
    x = global_to_local(PoseValue{truth_->q_GtoI, truth_->p_IinG}, global);
  }
  target_ = std::make_shared<TargetState>();
  target_->set_value(x.to_vector());
  target_->set_fej(x.to_vector());
  const TargetInitSigmas& s = options_.init_sigmas;
  Vector12d d;
  d << Eigen::Vector3d::Constant(s.theta * s.theta), Eigen::Vector3d::Constant(s.p * s.p),
      Eigen::Vector3d::Constant(s.v * s.v), Eigen::Vector3d::Constant(s.w * s.w);
  StateHelper::add_variable(state, target_, Eigen::MatrixXd(d.asDiagonal()));
  if (state.clone_at(utime)) on_clone_added(state, utime);
  return true;
}

void TargetFilter::update(State& state, int64_t utime, const std::vector<FeatureObservation>& obs) {
  if (!target_) {
    if (obs.empty() || !initialize_from_truth(state, utime)) return;
  }
  if (options_.mode == TargetUpdateMode::kOff) return;
  stats_.obs_received += static_cast<int64_t>(obs.size());
  if (clones_.count(utime) != 0) {
    for (const auto& o : obs) tracks_.add(utime, o.feature_id, o.camera_id, o.normalized);
  }
  std::vector<std::shared_ptr<estimator::Feature>> use = tracks_.lost_before(utime);
  if (static_cast<int>(state.clones().size()) > state.options().max_clones) {
    for (const auto& f : tracks_.observed_at(state.oldest_clone_utime())) {
      if (f->last_utime() >= utime) use.push_back(f);
    }
  }
  for (const auto& f : use) tracks_.remove(f->feature_id);
  update_tracks(state, std::move(use));
}

void TargetFilter::update_tracks(State& state, std::vector<std::shared_ptr<estimator::Feature>> tracks) {
  if (tracks.empty()) return;
  const bool global = options_.representation == TargetRepresentation::kGlobal;
  const auto& cameras = estimator_.cameras();
  std::set<int64_t> times;
  estimator::ClonePoses poses_in_T;  // IMU pose at each clone time in the target frame
  for (const auto& kv : clones_) {
    const auto imu_clone = state.clone_at(kv.first);
    if (!imu_clone) continue;
    times.insert(kv.first);
    const Eigen::Matrix3d R_RtoT = kv.second->Rot();
    const Eigen::Vector3d p_TinR = kv.second->pos();
    estimator::ClonePose cp;
    if (global) {
      cp.R_GtoI = imu_clone->Rot() * R_RtoT.transpose();
      cp.p_IinG = R_RtoT * (imu_clone->pos() - p_TinR);
    } else {
      cp.R_GtoI = R_RtoT.transpose();
      cp.p_IinG = -R_RtoT * p_TinR;
    }
    poses_in_T[kv.first] = cp;
  }
  const estimator::FeatureTriangulator triangulator(options_.triangulation, cameras);

  estimator::ColumnLayout layout;
  for (const auto& kv : clones_) {
    if (times.count(kv.first) == 0) continue;
    layout.col(kv.second);
    if (global) layout.col(state.clone_at(kv.first));
  }
  const Eigen::MatrixXd P_xx = StateHelper::marginal_covariance(state, layout.order());

  std::vector<Eigen::MatrixXd> Hs;
  std::vector<Eigen::VectorXd> rs;
  int total_rows = 0;
  std::sort(tracks.begin(), tracks.end(),
            [](const auto& a, const auto& b) { return a->feature_id < b->feature_id; });
  for (auto& f : tracks) {
    f->keep_times(times);
    if (static_cast<int>(f->times().size()) < options_.min_clone_times) {
      ++stats_.rejected_short;
      continue;
    }
    if (!triangulator.triangulate(*f, poses_in_T)) {
      ++stats_.rejected_triangulation;
      continue;
    }
    const Eigen::Vector3d p_FinT = f->p_FinG;
    const int m = f->num_obs();
    Eigen::MatrixXd H_x = Eigen::MatrixXd::Zero(2 * m, layout.total());
    Eigen::MatrixXd H_f = Eigen::MatrixXd::Zero(2 * m, 3);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(2 * m);
    bool ok = true;
    int row = 0;
    for (const auto& kv : f->obs) {
      const estimator::CameraInfo& cam = cameras[static_cast<size_t>(kv.first)];
      const CameraExtrinsics ext{cam.R_ItoC, cam.p_IinC};
      for (const auto& o : kv.second) {
        const auto tclone = clones_.at(o.utime);
        const auto iclone = state.clone_at(o.utime);
        const PoseValue imu_pose{iclone->quat(), iclone->pos()};
        const PoseValue tgt_pose{tclone->quat(), tclone->pos()};
        const TargetPointPrediction pred =
            predict_target_point(options_.representation, imu_pose, tgt_pose, p_FinT, ext);
        if (!pred.valid) ok = false;
        const Eigen::Matrix2d W = cam.whitening(o.uv);
        H_x.block<2, 6>(row, layout.col(tclone)) = W * pred.H_target_pose;
        if (global) H_x.block<2, 6>(row, layout.col(iclone)) = W * pred.H_imu_pose;
        H_f.block<2, 3>(row, 0) = W * pred.H_point;
        r.segment<2>(row) = W * (o.uv - pred.z);
        row += 2;
      }
    }
    if (!ok) {
      ++stats_.rejected_triangulation;
      continue;
    }
    const Eigen::VectorXd r_raw = r;
    estimator::nullspace_project_inplace(H_f, H_x, r);
    if (r.size() == 0) {
      ++stats_.rejected_triangulation;
      continue;
    }
    Eigen::MatrixXd S = H_x * P_xx * H_x.transpose();
    S.diagonal().array() += 1.0;
    const double chi2 = r.dot(S.llt().solve(r));
    if (!(chi2 < options_.chi2_multiplier * estimator::chi2_95(static_cast<int>(r.size())))) {
      ++stats_.rejected_chi2;
      continue;
    }
    ++stats_.tracks_used;
    stats_.obs_used += m;
    stats_.residual_sum += r_raw.sum();
    stats_.residual_sq_sum += r_raw.squaredNorm();
    stats_.residual_count += r_raw.size();
    total_rows += static_cast<int>(r.size());
    Hs.push_back(std::move(H_x));
    rs.push_back(std::move(r));
  }
  if (total_rows == 0) return;
  stats_.rows += total_rows;
  Eigen::MatrixXd H(total_rows, layout.total());
  Eigen::VectorXd r(total_rows);
  int row = 0;
  for (size_t i = 0; i < Hs.size(); ++i) {
    const int n = static_cast<int>(rs[i].size());
    H.middleRows(row, n) = Hs[i];
    r.segment(row, n) = rs[i];
    row += n;
  }
  estimator::measurement_compress_inplace(H, r);
  const Eigen::MatrixXd R = Eigen::MatrixXd::Identity(r.size(), r.size());
  bool applied = false;
  if (options_.mode == TargetUpdateMode::kEkf) {
    applied = StateHelper::ekf_update(state, layout.order(), H, r, R);
  } else {
    std::vector<TypePtr> nuisance;
    for (const auto& v : state.variables()) {
      if (v == target_) continue;
      bool is_clone = false;
      for (const auto& kv : clones_) is_clone = is_clone || kv.second == v;
      if (!is_clone) nuisance.push_back(v);
    }
    applied = StateHelper::schmidt_update(state, layout.order(), H, r, R, nuisance);
  }
  if (applied) ++stats_.updates;
}

}  // namespace target
}  // namespace vimot

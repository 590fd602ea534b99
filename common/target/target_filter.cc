#include "common/target/target_filter.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <random>
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
namespace {

PoseValue pose_of(const estimator::PoseJPL& pose) { return PoseValue{pose.quat(), pose.pos()}; }
PoseValue fej_pose_of(const estimator::PoseJPL& pose) { return PoseValue{pose.fej().head<4>(), pose.pos_fej()}; }

// The prediction z at the current estimates with the Jacobians at the first
// estimates (FEJ): linearising every measurement of the target pose and its
// points at one point keeps the unobservable directions (target yaw and
// origin vs its points) unobservable; current-estimate Jacobians would let
// the filter gain spurious information along them.
TargetPointPrediction predict_fej(TargetRepresentation representation, const estimator::PoseJPL& imu_pose,
                                  const estimator::PoseJPL& target_pose, const Eigen::Vector3d& p_FinT,
                                  const Eigen::Vector3d& p_FinT_fej, const CameraExtrinsics& cam, bool use_fej) {
  TargetPointPrediction pred = predict_target_point(representation, pose_of(imu_pose), pose_of(target_pose), p_FinT, cam);
  if (!use_fej) return pred;
  const TargetPointPrediction lin =
      predict_target_point(representation, fej_pose_of(imu_pose), fej_pose_of(target_pose), p_FinT_fej, cam);
  pred.valid = pred.valid && lin.valid;
  pred.H_imu_pose = lin.H_imu_pose;
  pred.H_target_pose = lin.H_target_pose;
  pred.H_point = lin.H_point;
  return pred;
}

}  // namespace

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

void TargetState::set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) {
  if (value.size() != 13 || fej.size() != 13) throw std::invalid_argument("TargetState::set_exact: expected 13");
  pose_->set_exact(value.head<7>(), fej.head<7>());
  v_->set_exact(value.segment<3>(7), fej.segment<3>(7));
  w_->set_exact(value.segment<3>(10), fej.segment<3>(10));
  Type::set_exact(value, fej);
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
TargetValue TargetState::get_fej() const { return TargetValue::from_vector(fej_); }

// ---------------------------------------------------------------- options
const char* to_string(TargetUpdateMode mode) {
  switch (mode) {
    case TargetUpdateMode::kOff: return "off";
    case TargetUpdateMode::kEkf: return "ekf";
    case TargetUpdateMode::kSkf: return "skf";
    case TargetUpdateMode::kAdaptive: return "adaptive";
  }
  return "unknown";
}

const char* to_string(TargetInitMode mode) {
  switch (mode) {
    case TargetInitMode::kFeatures: return "features";
    case TargetInitMode::kGroundTruth: return "ground_truth";
  }
  return "unknown";
}

TargetNoise TargetFilterOptions::noise(double sigma) const {
  return planar ? TargetNoise::planar(sigma, sigma) : TargetNoise::isotropic(sigma, sigma);
}

// ---------------------------------------------------------------- filter
TargetFilter::TargetFilter(estimator::VioEstimator& estimator, const TargetFilterOptions& options)
    : estimator_(estimator), options_(options), noise_(options.noise()) {
  if (!noise_.valid() || !(options_.sigma_t >= 0.0)) throw std::invalid_argument("TargetFilterOptions: bad sigma_t");
  if (!(options_.chi2_multiplier > 0.0)) throw std::invalid_argument("TargetFilterOptions: chi2_multiplier must be > 0");
  if (options_.min_clone_times < 2) throw std::invalid_argument("TargetFilterOptions: min_clone_times must be >= 2");
  if (options_.max_target_points < 0 || options_.point_init_clone_times < 2 || options_.point_max_lost_frames < 1) {
    throw std::invalid_argument("TargetFilterOptions: need max_target_points >= 0, point_init_clone_times >= 2 and "
                                "point_max_lost_frames >= 1");
  }
  const TargetFeatureInit& fi = options_.feature_init;
  if (fi.frames < 2 || fi.min_points < 1 || !(fi.max_point_distance > 0.0) || !(fi.sigma_w > 0.0)) {
    throw std::invalid_argument("TargetFilterOptions: feature_init needs frames >= 2, min_points >= 1 and "
                                "max_point_distance, sigma_w > 0");
  }
  if (options_.mode == TargetUpdateMode::kAdaptive) {
    adaptive_.emplace(options_.adaptive, options_.sigma_t);  // validates the options
    noise_ = options_.noise(adaptive_->sigma());
  }
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
  points_.clear();
  feature_init_info_.reset();
  init_window_.clear();
  frame_ = 0;
  starts_ = 0;
  model_verified_ = false;
  sigma_at_start_ = 0.0;
  predicted_.reset();
  if (adaptive_) {
    adaptive_.emplace(options_.adaptive, options_.sigma_t);
    noise_ = options_.noise(adaptive_->sigma());
  }
}

void TargetFilter::restore(std::shared_ptr<TargetState> target, std::map<int64_t, std::shared_ptr<PoseJPL>> clones,
                           std::map<int64_t, TargetPoint> points, estimator::FeatureDatabase tracks, int64_t frame,
                           std::optional<AdaptiveNoise> adaptive, int32_t starts, bool model_verified,
                           double sigma_at_start) {
  reset();
  target_ = std::move(target);
  clones_ = std::move(clones);
  points_ = std::move(points);
  tracks_ = std::move(tracks);
  frame_ = frame;
  starts_ = starts;
  model_verified_ = model_verified;
  sigma_at_start_ = sigma_at_start;
  if (adaptive_ && adaptive) {
    adaptive_ = std::move(adaptive);
    noise_ = options_.noise(adaptive_->sigma());
  }
}

bool TargetFilter::tightly_coupled() const {
  return options_.mode == TargetUpdateMode::kEkf || (adaptive_ && adaptive_->consistent());
}

std::vector<int> TargetFilter::driven_components() const {
  if (options_.planar) return {6, 7, 11};
  return {6, 7, 8, 9, 10, 11};
}

TargetFilter::Predicted TargetFilter::driven_now(const State& state, double dt) const {
  const std::vector<int> idx = driven_components();
  const Eigen::VectorXd x = target_->value();  // error index i ↔ value index i + 1 for i >= 3
  Predicted out;
  out.x.resize(static_cast<Eigen::Index>(idx.size()));
  out.P.resize(static_cast<Eigen::Index>(idx.size()));
  for (size_t k = 0; k < idx.size(); ++k) {
    out.x(static_cast<Eigen::Index>(k)) = x(idx[k] + 1);
    out.P(static_cast<Eigen::Index>(k)) = state.cov()(target_->id() + idx[k], target_->id() + idx[k]);
  }
  out.dt = dt;
  return out;
}

void TargetFilter::apply_inflation(State& state) {
  noise_ = options_.noise(adaptive_->sigma());
  if (!(adaptive_->inflation() > 0.0)) return;
  // Process noise the rejected σ left out (adaptive_noise.h), through the
  // target's motion over the time it was used: the pose integrated it too.
  const double tau = adaptive_->inflation_time();
  const estimator::ImuValue imu = state.imu()->get();
  const TargetStep missed = propagate_target(options_.representation, target_->get(), imu, imu, Matrix15d::Identity(),
                                             Matrix15d::Zero(), tau, options_.noise(std::sqrt(adaptive_->inflation() / tau)));
  StateHelper::propagate(state, {target_}, Matrix12d::Identity(), missed.Q_TT);
}

void TargetFilter::end_adaptive_frame(State& state) {
  if (!adaptive_ || !target_) return;
  if (!predicted_ || inflated_this_frame_) {
    adaptive_->end_frame_innovations_only(predicted_ ? predicted_->dt : 0.0);
  } else {
    const Predicted now = driven_now(state, 0.0);
    adaptive_->end_frame(predicted_->x, predicted_->P, now.x, now.P, predicted_->dt);
  }
  apply_inflation(state);
  predicted_.reset();
  inflated_this_frame_ = false;
  ++stats_.adaptive_frames;
  if (adaptive_->consistent()) ++stats_.adaptive_coupled_frames;
  stats_.adaptive_violations = adaptive_->violations();
  stats_.adaptive_sigma_sum += adaptive_->sigma();
  stats_.adaptive_sigma_last = adaptive_->sigma();
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
  pending_dt_ = dt;
  TargetStep step = propagate_target(options_.representation, target_->get(), x0, x1, Phi_II, Q_II, dt, noise_);
  if (state.options().use_fej) {
    // Φ and Q at the first estimates of the target and IMU at t_k (x1 is its own
    // first estimate), as the estimator's own IMU Φ_II.
    const TargetStep lin = propagate_target(options_.representation, target_->get_fej(), state.imu()->get_fej(), x1,
                                            Phi_II, Q_II, dt, noise_);
    step.Phi_TT = lin.Phi_TT;
    step.Phi_TI = lin.Phi_TI;
    step.Q_TT = lin.Q_TT;
    step.Q_TI = lin.Q_TI;
    // The next first estimate is the propagated current estimate, not the
    // propagated first estimate: without the constraint Φ maps the gauge onto
    // the wrong directions by the last update of v, w and the pose, and the
    // target frame gains information its points do not give.
    if (options_.observability_constraint) {
      constrain_observability(
          joint_unobservable_directions(options_.representation, state.imu()->get_fej(), target_->get_fej()),
          joint_unobservable_directions(options_.representation, x1, step.x),
          noise_invariant_directions(options_.planar), &step);
    }
  }
  Eigen::Matrix<double, 27, 27> F, Qd;
  joint_transition(Phi_II, Q_II, step, &F, &Qd);
  *order = {state.imu(), target_};
  *Phi = F;
  *Q = Qd;
  pending_ = step.x;
  return true;
}

void TargetFilter::commit_propagation(State& state) {
  if (!target_ || !pending_) return;
  const Eigen::VectorXd v = pending_->to_vector();
  target_->set_value(v);
  target_->set_fej(v);
  pending_.reset();
  if (adaptive_) predicted_ = driven_now(state, pending_dt_);
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
  TargetState start;
  start.set_value(x.to_vector());
  const TargetInitSigmas& s = options_.init_sigmas;
  Vector12d sigma;
  sigma << Eigen::Vector3d::Constant(s.theta), Eigen::Vector3d::Constant(s.p), Eigen::Vector3d::Constant(s.v),
      Eigen::Vector3d::Constant(s.w);
  if (options_.init_perturb_seed != 0) {
    // Its own stream: the IMU start perturbation uses the same seed.
    std::mt19937_64 rng(options_.init_perturb_seed ^ 0x7461726765740000ull);
    std::normal_distribution<double> n01(0.0, 1.0);
    Vector12d dx;
    for (int i = 0; i < 12; ++i) dx(i) = sigma(i) * n01(rng);
    start.update(dx);
  }
  add_target(state, utime, start.get(), sigma.cwiseAbs2().asDiagonal(), Eigen::MatrixXd());
  return true;
}

void TargetFilter::add_target(State& state, int64_t utime, const TargetValue& x, const Matrix12d& P_TT,
                              const Eigen::MatrixXd& P_Tx) {
  ++starts_;
  if (adaptive_) sigma_at_start_ = adaptive_->sigma();
  target_ = std::make_shared<TargetState>();
  target_->set_value(x.to_vector());
  target_->set_fej(x.to_vector());
  StateHelper::add_variable(state, target_, P_TT, P_Tx);
  if (state.clone_at(utime)) on_clone_added(state, utime);
}

std::optional<TargetFilter::StereoPoints> TargetFilter::stereo_target_points(
    const State& state, int64_t utime, const std::vector<FeatureObservation>& obs) const {
  // Target features seen by at least two cameras now, triangulated in I from
  // this frame alone (identity pose: the triangulator's "G" is I).
  const auto& cameras = estimator_.cameras();
  std::map<int64_t, estimator::Feature> by_id;
  for (const auto& o : obs) {
    if (o.camera_id < 0 || o.camera_id >= static_cast<int>(cameras.size())) continue;
    estimator::Feature& f = by_id[o.feature_id];
    f.feature_id = o.feature_id;
    f.obs[o.camera_id].push_back(estimator::FeatureObs{utime, o.normalized});
  }
  const estimator::ClonePoses now{{utime, estimator::ClonePose{}}};
  const estimator::FeatureTriangulator triangulator(options_.triangulation, cameras);
  StereoPoints pts;
  pts.utime = utime;
  for (auto& kv : by_id) {
    estimator::Feature& f = kv.second;
    if (f.obs.size() < 2 || !triangulator.triangulate(f, now)) continue;
    // Covariance from the whitened projection Jacobians of its views (Gauss–Newton information).
    Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
    for (const auto& cam_obs : f.obs) {
      const estimator::CameraInfo& cam = cameras[static_cast<size_t>(cam_obs.first)];
      const Eigen::Vector3d p_FinC = cam.R_ItoC * f.p_FinG + cam.p_IinC;
      for (const auto& o : cam_obs.second) {
        const Eigen::Matrix<double, 2, 3> H = cam.whitening(o.uv) * estimator::project_jacobian(p_FinC) * cam.R_ItoC;
        info += H.transpose() * H;
      }
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(info);
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) continue;
    pts.p_FinI[f.feature_id] = f.p_FinG;
    pts.cov_I[f.feature_id] = ldlt.solve(Eigen::Matrix3d::Identity());
  }
  if (static_cast<int>(pts.p_FinI.size()) < options_.feature_init.min_points) return std::nullopt;
  // Mismatched or mislabelled features: drop those far from the per-axis median.
  Eigen::Vector3d median;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> c;
    for (const auto& kv : pts.p_FinI) c.push_back(kv.second(k));
    std::nth_element(c.begin(), c.begin() + static_cast<long>(c.size() / 2), c.end());
    median(k) = c[c.size() / 2];
  }
  for (auto it = pts.p_FinI.begin(); it != pts.p_FinI.end();) {
    if ((it->second - median).norm() > options_.feature_init.max_point_distance) {
      pts.cov_I.erase(it->first);
      it = pts.p_FinI.erase(it);
    } else {
      ++it;
    }
  }
  if (static_cast<int>(pts.p_FinI.size()) < options_.feature_init.min_points) return std::nullopt;
  pts.imu = state.imu()->get();
  return pts;
}

bool TargetFilter::initialize_from_features(State& state, int64_t utime, const std::vector<FeatureObservation>& obs) {
  std::optional<StereoPoints> now = stereo_target_points(state, utime, obs);
  if (!now) {
    init_window_.clear();  // the frames of the window must be consecutive
    return false;
  }
  init_window_.push_back(std::move(*now));
  while (static_cast<int>(init_window_.size()) > options_.feature_init.frames) init_window_.pop_front();
  if (static_cast<int>(init_window_.size()) < options_.feature_init.frames) return false;
  // The features seen in every frame of the window: one fixed set of body points.
  std::vector<int64_t> ids;
  for (const auto& kv : init_window_.back().p_FinI) {
    bool everywhere = true;
    for (const StereoPoints& f : init_window_) everywhere = everywhere && f.p_FinI.count(kv.first) != 0;
    if (everywhere) ids.push_back(kv.first);
  }
  if (static_cast<int>(ids.size()) < options_.feature_init.min_points) {
    init_window_.pop_front();
    return false;
  }
  // Their centroid in G per frame (the robot's estimates then) and its
  // covariance from the triangulations; the velocity is the least-squares
  // slope of the centroids over time.
  const double n = static_cast<double>(ids.size());
  const int64_t t_ref = init_window_.back().utime;
  std::vector<double> t;
  std::vector<Eigen::Vector3d> c_G;
  Eigen::Matrix3d cov_G_mean = Eigen::Matrix3d::Zero();
  TargetFeatureInitInfo info;
  info.utime = utime;
  info.feature_ids = ids;
  for (const StereoPoints& f : init_window_) {
    Eigen::Vector3d c_I = Eigen::Vector3d::Zero();
    Eigen::Matrix3d cov_I = Eigen::Matrix3d::Zero();
    for (const int64_t id : ids) {
      c_I += f.p_FinI.at(id);
      cov_I += f.cov_I.at(id);
    }
    c_I /= n;
    cov_I /= n * n;
    const Eigen::Matrix3d R_ItoG = quat_to_rot(f.imu.q_GtoI).transpose();
    t.push_back(utime_to_seconds(f.utime - t_ref));
    c_G.push_back(f.imu.p_IinG + R_ItoG * c_I);
    cov_G_mean += R_ItoG * cov_I * R_ItoG.transpose() / static_cast<double>(init_window_.size());
    info.centroid_in_I = c_I;  // the last frame's
    info.centroid_cov = cov_I;
  }
  double t_mean = 0.0;
  Eigen::Vector3d c_mean = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < t.size(); ++k) {
    t_mean += t[k] / static_cast<double>(t.size());
    c_mean += c_G[k] / static_cast<double>(t.size());
  }
  double stt = 0.0;
  Eigen::Vector3d stc = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < t.size(); ++k) {
    stt += (t[k] - t_mean) * (t[k] - t_mean);
    stc += (t[k] - t_mean) * (c_G[k] - c_mean);
  }
  if (!(stt > 0.0)) return false;
  const Eigen::Vector3d v_G = stc / stt;
  init_window_.clear();

  // T at this frame: origin at the centroid, R_GtoT = I (so R_ItoT = R̂_GtoIᵀ
  // and v_TinT = v_TinG), w = 0.
  const PoseValue imu = imu_pose(state.imu()->get());
  TargetValue local;
  local.q_RtoT = quat_inverse(imu.q);
  local.p_TinR = info.centroid_in_I;
  local.v_TinT = v_G;
  // Error of the local start: the pose is the gauge (init_sigmas.theta, p);
  // v = the centroids' slope, whose error is the triangulation noise's slope
  // plus the robot's velocity error (the centroids are placed in G with the
  // robot's estimates; its pose error over the short window is dominated by
  // δv_I · Δt, the rotation terms |v_rel| σ_θ are far below the noise); w
  // has the broad prior, except the axes the planar model keeps at zero.
  const TargetInitSigmas& s = options_.init_sigmas;
  const double sw = options_.feature_init.sigma_w;
  Matrix12d N_L = Matrix12d::Zero();
  N_L.diagonal() << Eigen::Vector3d::Constant(s.theta * s.theta), Eigen::Vector3d::Constant(s.p * s.p),
      Eigen::Vector3d::Zero(),
      (options_.planar ? Eigen::Vector3d(s.w, s.w, sw) : Eigen::Vector3d::Constant(sw)).cwiseAbs2();
  N_L.block<3, 3>(6, 6) = cov_G_mean / stt;
  const int N = state.cov().rows();
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(12, N);  // ∂δx_T/∂δx (robot and the rest of the state)
  B.block<3, 3>(6, state.imu()->v()->id()) = Eigen::Matrix3d::Identity();
  Matrix12d N_T = N_L;
  TargetValue x = local;
  if (options_.representation == TargetRepresentation::kGlobal) {
    // δx_G = J_T δx_L + J_I δ[θ_I p_I]: the robot's pose error enters T in G.
    Matrix12x6d J_I;
    Matrix12d J_T;
    x = local_to_global(imu, local, &J_I, &J_T);
    B = J_T * B;
    B.middleCols(state.imu()->pose()->id(), 6) += J_I;
    N_T = J_T * N_L * J_T.transpose();
  }
  const Eigen::MatrixXd P_Tx = B * state.cov();
  Matrix12d P_TT = B * P_Tx.transpose() + N_T;
  P_TT = 0.5 * (P_TT + P_TT.transpose()).eval();
  add_target(state, utime, x, P_TT, P_Tx);
  feature_init_info_ = std::move(info);
  return true;
}

void TargetFilter::update(State& state, int64_t utime, const std::vector<FeatureObservation>& obs) {
  if (!target_) {
    // (A frame without target features also breaks the features start's window.)
    const bool started = options_.init_mode == TargetInitMode::kGroundTruth
                             ? !obs.empty() && initialize_from_truth(state, utime)
                             : initialize_from_features(state, utime, obs);
    if (!started) return;
  }
  if (options_.mode == TargetUpdateMode::kOff) return;
  ++frame_;
  stats_.obs_received += static_cast<int64_t>(obs.size());
  const bool at_clone = clones_.count(utime) != 0;
  std::vector<FeatureObservation> point_obs;
  for (const auto& o : obs) {
    if (points_.count(o.feature_id) != 0) {
      point_obs.push_back(o);
    } else if (at_clone) {
      tracks_.add(utime, o.feature_id, o.camera_id, o.normalized);
    }
  }
  // 1. In-state target points: update with their current observations.
  update_points(state, point_obs);
  // 2. Points not updated for a while leave the state.
  std::vector<int64_t> lost;
  for (const auto& kv : points_) {
    if (frame_ - kv.second.last_updated_frame >= options_.point_max_lost_frames) lost.push_back(kv.first);
  }
  for (const int64_t id : lost) marginalize_point(state, id);
  // 3. Delayed initialisation of long tracks still seen now.
  if (at_clone && options_.max_target_points > 0) initialize_points(state, utime);
  // 4. MSCKF-style update of the other tracks.
  std::vector<std::shared_ptr<estimator::Feature>> use = tracks_.lost_before(utime);
  if (static_cast<int>(state.clones().size()) > state.options().max_clones) {
    for (const auto& f : tracks_.observed_at(state.oldest_clone_utime())) {
      if (f->last_utime() >= utime) use.push_back(f);
    }
  }
  for (const auto& f : use) tracks_.remove(f->feature_id);
  update_tracks(state, std::move(use));
  end_adaptive_frame(state);
  if (adaptive_ && !model_verified_ && adaptive_->consistent()) {
    model_verified_ = true;
    // A target started under a σ too small has made its frame and points
    // under it: an error made then along its gauge (where its origin sits
    // among its points) no later measurement can see. So it starts again
    // from its features under the σ now verified. Too small: more than one
    // violation's largest step (σ² · max_step) below that σ. A start under
    // a σ too large is kept: it makes no such error (the risk is one-sided,
    // as for the hold).
    const double sigma = adaptive_->sigma();
    const bool started_too_small = sigma * sigma > options_.adaptive.max_step * sigma_at_start_ * sigma_at_start_;
    if (options_.adaptive.restart && started_too_small && options_.init_mode == TargetInitMode::kFeatures) {
      restart_target(state);
    }
  }
}

void TargetFilter::restart_target(State& state) {
  for (const auto& kv : clones_) StateHelper::marginalize(state, kv.second);
  for (const auto& kv : points_) StateHelper::marginalize(state, kv.second.var);
  StateHelper::marginalize(state, target_);
  target_.reset();
  clones_.clear();
  points_.clear();
  pending_.reset();
  tracks_.clear();
  feature_init_info_.reset();
  init_window_.clear();
  predicted_.reset();
  ++stats_.target_restarts;
}

estimator::ClonePoses TargetFilter::poses_in_target(const State& state, std::set<int64_t>* times) const {
  const bool global = options_.representation == TargetRepresentation::kGlobal;
  estimator::ClonePoses poses_in_T;  // IMU pose at each clone time in the target frame
  for (const auto& kv : clones_) {
    const auto imu_clone = state.clone_at(kv.first);
    if (!imu_clone) continue;
    times->insert(kv.first);
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
  return poses_in_T;
}

std::vector<TypePtr> TargetFilter::nuisance_variables(const State& state) const {
  std::vector<TypePtr> nuisance;
  for (const auto& v : state.variables()) {
    if (v == target_) continue;
    bool active = false;
    for (const auto& kv : clones_) active = active || kv.second == v;
    for (const auto& kv : points_) active = active || kv.second.var == v;
    if (!active) nuisance.push_back(v);
  }
  return nuisance;
}

bool TargetFilter::apply_update(State& state, const std::vector<TypePtr>& order, const Eigen::MatrixXd& H,
                                const Eigen::VectorXd& r) {
  const Eigen::MatrixXd R = Eigen::MatrixXd::Identity(r.size(), r.size());
  if (tightly_coupled()) return StateHelper::ekf_update(state, order, H, r, R);
  return StateHelper::schmidt_update(state, order, H, r, R, nuisance_variables(state));
}

void TargetFilter::marginalize_point(State& state, int64_t feature_id) {
  const auto it = points_.find(feature_id);
  if (it == points_.end()) return;
  StateHelper::marginalize(state, it->second.var);
  points_.erase(it);
  ++stats_.points_marginalized;
}

void TargetFilter::update_points(State& state, const std::vector<FeatureObservation>& obs) {
  if (obs.empty()) return;
  const bool global = options_.representation == TargetRepresentation::kGlobal;
  const auto& cameras = estimator_.cameras();
  std::map<int64_t, std::vector<const FeatureObservation*>> by_point;
  for (const auto& o : obs) {
    if (o.camera_id < 0 || o.camera_id >= static_cast<int>(cameras.size())) continue;
    by_point[o.feature_id].push_back(&o);
  }
  const bool use_fej = state.options().use_fej;
  struct Block {
    int64_t id;
    TypePtr point;
    Eigen::MatrixXd H;  // [target pose (6), IMU pose (6, global), point (3)]
    Eigen::VectorXd r;
    std::vector<TypePtr> order;
    double chi2;
  };
  std::vector<Block> candidates;
  for (const auto& kv : by_point) {
    TargetPoint& pt = points_.at(kv.first);
    // The first triangulation can be centimetres off, a large error in the
    // lever arm of T's orientation; moving the linearisation point with the
    // covariance carried along the gauge keeps the gauge out of the update.
    if (use_fej && options_.relinearize_points && pt.var->value() != pt.var->fej()) {
      const Eigen::Matrix3d R_ItoT = global ? Eigen::Matrix3d(target_->pose()->Rot_fej() *
                                                              state.imu()->pose()->Rot_fej().transpose())
                                            : target_->pose()->Rot_fej();
      std::vector<TypePtr> order{target_->pose()};
      if (global) order.push_back(state.imu()->pose());
      order.push_back(pt.var);
      StateHelper::transform_variable(
          state, pt.var, order,
          point_relinearization(options_.representation, R_ItoT, pt.var->fej(), pt.var->value()));
      pt.var->set_fej(pt.var->value());
    }
    const Eigen::Vector3d p_FinT = pt.var->value();
    const Eigen::Vector3d p_FinT_fej = pt.var->fej();
    const int m = static_cast<int>(kv.second.size());
    const int nx = global ? 15 : 9;
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(2 * m, nx);
    Eigen::VectorXd r(2 * m);
    int row = 0;
    for (const FeatureObservation* o : kv.second) {
      const estimator::CameraInfo& cam = cameras[static_cast<size_t>(o->camera_id)];
      const TargetPointPrediction pred = predict_fej(options_.representation, *state.imu()->pose(), *target_->pose(),
                                                     p_FinT, p_FinT_fej, CameraExtrinsics{cam.R_ItoC, cam.p_IinC}, use_fej);
      if (!pred.valid) continue;
      const Eigen::Matrix2d W = cam.whitening(o->normalized);
      H.block<2, 6>(row, 0) = W * pred.H_target_pose;
      if (global) H.block<2, 6>(row, 6) = W * pred.H_imu_pose;
      H.block<2, 3>(row, nx - 3) = W * pred.H_point;
      r.segment<2>(row) = W * (o->normalized - pred.z);
      row += 2;
    }
    if (row == 0) continue;
    H.conservativeResize(row, nx);
    r.conservativeResize(row);
    std::vector<TypePtr> order{target_->pose()};
    if (global) order.push_back(state.imu()->pose());
    order.push_back(pt.var);
    candidates.push_back(Block{kv.first, pt.var, std::move(H), std::move(r), std::move(order), 0.0});
  }
  const auto compute_chi2 = [&state, &candidates](double* sum, int* dof) {
    *sum = 0.0;
    *dof = 0;
    for (Block& b : candidates) {
      Eigen::MatrixXd S = b.H * StateHelper::marginal_covariance(state, b.order) * b.H.transpose();
      S.diagonal().array() += 1.0;
      b.chi2 = b.r.dot(S.llt().solve(b.r));
      *sum += b.chi2;
      *dof += static_cast<int>(b.r.size());
    }
  };
  double chi2_sum = 0.0;
  int dof = 0;
  compute_chi2(&chi2_sum, &dof);
  // Adaptive: a frame whose points already violate the model takes the σ
  // steps before its update (until the gate accepts them, or σ is at its
  // maximum), so its measurements correct the target rather than being
  // gated out while σ is bracketed frame by frame: the target would drift
  // meanwhile, and points initialised then fix a wrong target frame for
  // good (docs/target_model.md, "Adaptive target noise").
  while (adaptive_ && predicted_ && adaptive_->inflate_before_update(chi2_sum, dof, predicted_->dt)) {
    inflated_this_frame_ = true;
    apply_inflation(state);
    compute_chi2(&chi2_sum, &dof);
  }
  std::vector<Block> accepted;
  int rows = 0;
  for (Block& b : candidates) {
    if (adaptive_) adaptive_->add_innovation(b.chi2, static_cast<int>(b.r.size()));
    if (!(b.chi2 < options_.chi2_multiplier * estimator::chi2_95(static_cast<int>(b.r.size())))) {
      ++stats_.points_rejected_chi2;
      continue;
    }
    points_.at(b.id).last_updated_frame = frame_;
    ++stats_.point_updates;
    stats_.obs_used += static_cast<int>(b.r.size()) / 2;
    rows += static_cast<int>(b.r.size());
    accepted.push_back(std::move(b));
  }
  if (accepted.empty()) return;
  estimator::ColumnLayout layout;
  layout.col(target_->pose());
  if (global) layout.col(state.imu()->pose());
  for (const auto& b : accepted) layout.col(b.point);
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(rows, layout.total());
  Eigen::VectorXd r(rows);
  int row = 0;
  for (const auto& b : accepted) {
    const int n = static_cast<int>(b.r.size());
    H.block(row, layout.col(target_->pose()), n, 6) = b.H.leftCols(6);
    if (global) H.block(row, layout.col(state.imu()->pose()), n, 6) = b.H.middleCols(6, 6);
    H.block(row, layout.col(b.point), n, 3) = b.H.rightCols(3);
    r.segment(row, n) = b.r;
    row += n;
  }
  stats_.rows += rows;
  apply_update(state, layout.order(), H, r);
}

estimator::ColumnLayout TargetFilter::clone_layout(const State& state, const std::set<int64_t>& times) const {
  const bool global = options_.representation == TargetRepresentation::kGlobal;
  estimator::ColumnLayout layout;
  for (const auto& kv : clones_) {
    if (times.count(kv.first) == 0) continue;
    layout.col(kv.second);
    if (global) layout.col(state.clone_at(kv.first));
  }
  return layout;
}

bool TargetFilter::track_system(const State& state, const estimator::Feature& f, const Eigen::Vector3d& p_FinT,
                                estimator::ColumnLayout& layout, Eigen::MatrixXd* H_x, Eigen::MatrixXd* H_f,
                                Eigen::VectorXd* r) const {
  const bool global = options_.representation == TargetRepresentation::kGlobal;
  const auto& cameras = estimator_.cameras();
  const int m = f.num_obs();
  *H_x = Eigen::MatrixXd::Zero(2 * m, layout.total());
  *H_f = Eigen::MatrixXd::Zero(2 * m, 3);
  *r = Eigen::VectorXd::Zero(2 * m);
  bool ok = true;
  int row = 0;
  for (const auto& kv : f.obs) {
    if (kv.first < 0 || kv.first >= static_cast<int>(cameras.size())) return false;
    const estimator::CameraInfo& cam = cameras[static_cast<size_t>(kv.first)];
    const CameraExtrinsics ext{cam.R_ItoC, cam.p_IinC};
    for (const auto& o : kv.second) {
      const auto tclone = clones_.at(o.utime);
      const auto iclone = state.clone_at(o.utime);
      const TargetPointPrediction pred =
          predict_fej(options_.representation, *iclone, *tclone, p_FinT, p_FinT, ext, state.options().use_fej);
      ok = ok && pred.valid;
      const Eigen::Matrix2d W = cam.whitening(o.uv);
      H_x->block<2, 6>(row, layout.col(tclone)) = W * pred.H_target_pose;
      if (global) H_x->block<2, 6>(row, layout.col(iclone)) = W * pred.H_imu_pose;
      H_f->block<2, 3>(row, 0) = W * pred.H_point;
      r->segment<2>(row) = W * (o.uv - pred.z);
      row += 2;
    }
  }
  return ok;
}

void TargetFilter::initialize_points(State& state, int64_t utime) {
  std::vector<std::shared_ptr<estimator::Feature>> cands;
  for (const auto& f : tracks_.observed_at(utime)) {
    if (static_cast<int>(f->times().size()) >= options_.point_init_clone_times) cands.push_back(f);
  }
  if (cands.empty()) return;
  // Make room: points not updated at this frame leave first (longest unseen first).
  int room = options_.max_target_points - static_cast<int>(points_.size());
  if (room < static_cast<int>(cands.size())) {
    std::vector<std::pair<int64_t, int64_t>> stale;  // (last updated frame, id)
    for (const auto& kv : points_) {
      if (kv.second.last_updated_frame < frame_) stale.emplace_back(kv.second.last_updated_frame, kv.first);
    }
    std::sort(stale.begin(), stale.end());
    for (const auto& s : stale) {
      if (room >= static_cast<int>(cands.size())) break;
      marginalize_point(state, s.second);
      ++room;
    }
  }
  if (room <= 0) return;
  std::sort(cands.begin(), cands.end(), [](const auto& a, const auto& b) {
    const int na = a->num_obs(), nb = b->num_obs();
    return na != nb ? na > nb : a->feature_id < b->feature_id;
  });
  const auto& cameras = estimator_.cameras();
  std::set<int64_t> times;
  const estimator::ClonePoses poses_in_T = poses_in_target(state, &times);
  const estimator::FeatureTriangulator triangulator(options_.triangulation, cameras);
  estimator::ColumnLayout layout = clone_layout(state, times);  // col() of a present variable only looks up
  int added = 0;
  for (auto& f : cands) {
    if (added >= room) break;
    f->keep_times(times);
    if (static_cast<int>(f->times().size()) < options_.point_init_clone_times || !triangulator.triangulate(*f, poses_in_T)) {
      ++stats_.points_rejected_init;
      continue;
    }
    const Eigen::Vector3d p_FinT = f->p_FinG;
    const int m = f->num_obs();
    Eigen::MatrixXd H_R, H_L;
    Eigen::VectorXd r;
    const bool ok = track_system(state, *f, p_FinT, layout, &H_R, &H_L, &r);
    if (!ok) {
      ++stats_.points_rejected_init;
      continue;
    }
    auto var = std::make_shared<estimator::Vec>(3);
    var->set_value(p_FinT);
    var->set_fej(p_FinT);
    bool initialized = false;
    if (tightly_coupled()) {
      initialized = StateHelper::initialize(state, var, layout.order(), H_R, H_L, r, 1.0, options_.chi2_multiplier);
    } else {
      // StateHelper::initialize with a Schmidt update of the remaining rows
      // (its EKF update would change the robot).
      estimator::givens_triangularize_inplace(H_L, H_R, r);
      const Eigen::Matrix3d U = H_L.topRows(3);
      const double dmax = U.diagonal().cwiseAbs().maxCoeff();
      if (dmax > 0.0 && U.diagonal().cwiseAbs().minCoeff() >= 1e-10 * dmax) {
        const int m_up = 2 * m - 3;
        const Eigen::MatrixXd H_up = H_R.bottomRows(m_up);
        const Eigen::VectorXd r_up = r.tail(m_up);
        Eigen::MatrixXd S = H_up * StateHelper::marginal_covariance(state, layout.order()) * H_up.transpose();
        S.diagonal().array() += 1.0;
        if (r_up.dot(S.llt().solve(r_up)) < options_.chi2_multiplier * estimator::chi2_95(m_up)) {
          StateHelper::initialize_invertible(state, var, layout.order(), H_R.topRows(3), U, r.head(3),
                                             Eigen::Matrix3d::Identity());
          points_[f->feature_id] = TargetPoint{var, frame_};  // active in the Schmidt update below
          apply_update(state, layout.order(), H_up, r_up);
          initialized = true;
        }
      }
    }
    if (!initialized) {
      ++stats_.points_rejected_init;
      continue;
    }
    points_[f->feature_id] = TargetPoint{var, frame_};
    tracks_.remove(f->feature_id);
    ++stats_.points_initialized;
    stats_.obs_used += m;
    ++added;
  }
}

void TargetFilter::update_tracks(State& state, std::vector<std::shared_ptr<estimator::Feature>> tracks) {
  if (tracks.empty()) return;
  const auto& cameras = estimator_.cameras();
  std::set<int64_t> times;
  const estimator::ClonePoses poses_in_T = poses_in_target(state, &times);
  const estimator::FeatureTriangulator triangulator(options_.triangulation, cameras);
  estimator::ColumnLayout layout = clone_layout(state, times);  // col() of a present variable only looks up
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
    const int m = f->num_obs();
    Eigen::MatrixXd H_x, H_f;
    Eigen::VectorXd r;
    const bool ok = track_system(state, *f, f->p_FinG, layout, &H_x, &H_f, &r);
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
    if (adaptive_) adaptive_->add_innovation(chi2, static_cast<int>(r.size()));
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
  Eigen::MatrixXd H;
  Eigen::VectorXd r;
  estimator::stack_and_compress(Hs, rs, layout.total(), &H, &r);
  const bool applied = apply_update(state, layout.order(), H, r);
  if (applied) ++stats_.updates;
}

}  // namespace target
}  // namespace vimot

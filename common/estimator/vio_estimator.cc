#include "common/estimator/vio_estimator.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/config/config.h"
#include "common/estimator/state_helper.h"
#include "common/math/quat.h"
#include "common/time/utime.h"

namespace vimot {
namespace estimator {

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

template <typename T>
void read(const Config& cfg, const std::string& key, T* value) {
  *value = cfg.get_or<T>(key, *value);
}

bool by_track_length(const std::shared_ptr<Feature>& a, const std::shared_ptr<Feature>& b) {
  const int na = a->num_obs(), nb = b->num_obs();
  return na != nb ? na > nb : a->feature_id < b->feature_id;
}

}  // namespace

const char* to_string(FrameStatus status) {
  switch (status) {
    case FrameStatus::kProcessed: return "processed";
    case FrameStatus::kNotInitialized: return "dropped: not initialized";
    case FrameStatus::kRejectedOutOfOrder: return "rejected: not after the state time";
    case FrameStatus::kNoImu: return "dropped: no IMU data";
    case FrameStatus::kDiverged: return "dropped: estimator diverged";
  }
  return "unknown";
}

// ---------------------------------------------------------------- options
void VioOptions::validate() const {
  auto fail = [](const std::string& key, const std::string& what) {
    throw std::invalid_argument(key + ": " + what);
  };
  if (state.max_clones < 2) fail("num_clones", "must be >= 2, got " + std::to_string(state.max_clones));
  if (state.max_slam < 0) fail("max_slam", "must be >= 0, got " + std::to_string(state.max_slam));
  if (slam.max_init_per_frame < 0) fail("max_slam_init_per_frame", "must be >= 0");
  if (slam.max_chi2_failures < 1) fail("slam_max_chi2_failures", "must be >= 1");
  if (msckf.max_features_per_update < 0) fail("max_msckf_in_update", "must be >= 0");
  if (!(msckf.chi2_multiplier > 0.0)) fail("msckf_chi2_multiplier", "must be > 0");
  if (!(slam.chi2_multiplier > 0.0)) fail("slam_chi2_multiplier", "must be > 0");
  if (!(sigma_px > 0.0)) fail("sigma_px", "must be > 0, got " + std::to_string(sigma_px));
  if (!(propagator.gravity_magnitude > 0.0)) fail("gravity_magnitude", "must be > 0");
  if (!(propagator.max_gap_s > 0.0)) fail("max_imu_gap_s", "must be > 0");
  if (!(propagator.buffer_s > 0.0)) fail("imu_buffer_s", "must be > 0");
  const ImuNoise& n = propagator.noise;
  if (!(n.sigma_w > 0.0)) fail("imu.gyroscope_noise_density", "must be > 0");
  if (!(n.sigma_a > 0.0)) fail("imu.accelerometer_noise_density", "must be > 0");
  if (!(n.sigma_wb >= 0.0)) fail("imu.gyroscope_random_walk", "must be >= 0");
  if (!(n.sigma_ab >= 0.0)) fail("imu.accelerometer_random_walk", "must be >= 0");
  if (!(propagator.gap_noise.sigma_w >= 0.0)) fail("imu_gap_noise.gyroscope_noise_density", "must be >= 0");
  if (!(propagator.gap_noise.sigma_a >= 0.0)) fail("imu_gap_noise.accelerometer_noise_density", "must be >= 0");
  if (!(triangulation.min_depth > 0.0)) fail("triangulation.min_depth", "must be > 0");
  if (!(triangulation.max_depth > triangulation.min_depth)) fail("triangulation.max_depth", "must be > min_depth");
  if (!(triangulation.max_condition > 1.0)) fail("triangulation.max_condition", "must be > 1");
  if (triangulation.max_iterations < 0) fail("triangulation.max_iterations", "must be >= 0");
  if (!(static_init.window_s > 0.0)) fail("init.window_s", "must be > 0");
  if (!(static_init.max_accel_std > 0.0)) fail("init.max_accel_std", "must be > 0");
  const double sig[] = {init_sigmas.theta_rp, init_sigmas.theta_yaw, init_sigmas.p,
                        init_sigmas.v,        init_sigmas.bg,        init_sigmas.ba};
  const char* sig_keys[] = {"init.sigma_theta_rp", "init.sigma_yaw", "init.sigma_p",
                            "init.sigma_v",        "init.sigma_bg",  "init.sigma_ba"};
  for (int i = 0; i < 6; ++i) {
    if (!(sig[i] > 0.0)) fail(sig_keys[i], "must be > 0");
  }
  if (!(divergence.max_position_correction_m > 0.0)) fail("divergence.max_position_correction_m", "must be > 0");
  if (!(divergence.max_velocity_mps > 0.0)) fail("divergence.max_velocity_mps", "must be > 0");
  if (cameras.empty()) fail("cameras", "at least cam0 is required");
  if (use_stereo && cameras.size() < 2) fail("use_stereo", "true needs cam1");
}

VioOptions VioOptions::from_config(const Config& cfg, const std::string& section) {
  return from_config(cfg, cfg, section);
}

VioOptions VioOptions::from_config(const Config& estimator_cfg, const Config& calibration_cfg,
                                   const std::string& section) {
  VioOptions o;
  const std::string s = section.empty() ? "" : section + ".";
  const Config& c = estimator_cfg;
  if (!section.empty()) {
    c.check_keys(section, {"num_clones", "max_slam", "use_fej", "slam_representation", "max_slam_init_per_frame",
                           "slam_max_chi2_failures", "max_msckf_in_update", "msckf_chi2_multiplier",
                           "slam_chi2_multiplier", "use_stereo", "sigma_px", "gravity_magnitude", "max_imu_gap_s",
                           "imu_buffer_s", "triangulation", "init", "divergence", "imu_noise", "imu_gap_noise"});
  }
  c.check_keys(s + "triangulation", {"min_depth", "max_depth", "max_condition", "max_iterations"});
  c.check_keys(s + "init", {"mode", "window_s", "max_accel_std", "sigma_theta_rp", "sigma_yaw", "sigma_p", "sigma_v",
                            "sigma_bg", "sigma_ba"});
  c.check_keys(s + "divergence", {"max_position_correction_m", "max_velocity_mps"});
  c.check_keys(s + "imu_gap_noise", {"gyroscope_noise_density", "accelerometer_noise_density"});
  c.check_keys(s + "imu_noise", {"gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                                 "accelerometer_random_walk"});
  read(c, s + "num_clones", &o.state.max_clones);
  read(c, s + "max_slam", &o.state.max_slam);
  read(c, s + "use_fej", &o.state.use_fej);
  std::string rep = "global_xyz";
  read(c, s + "slam_representation", &rep);
  if (rep == "global_xyz") {
    o.state.slam_representation = LandmarkRepresentation::kGlobalXyz;
  } else if (rep == "anchored_inverse_depth") {
    o.state.slam_representation = LandmarkRepresentation::kAnchoredInverseDepth;
  } else {
    throw ConfigError(c.source() + ": " + s + "slam_representation: expected global_xyz or "
                      "anchored_inverse_depth, got '" + rep + "'");
  }
  read(c, s + "max_slam_init_per_frame", &o.slam.max_init_per_frame);
  read(c, s + "slam_max_chi2_failures", &o.slam.max_chi2_failures);
  read(c, s + "max_msckf_in_update", &o.msckf.max_features_per_update);
  read(c, s + "msckf_chi2_multiplier", &o.msckf.chi2_multiplier);
  read(c, s + "slam_chi2_multiplier", &o.slam.chi2_multiplier);
  read(c, s + "use_stereo", &o.use_stereo);
  read(c, s + "sigma_px", &o.sigma_px);
  read(c, s + "gravity_magnitude", &o.propagator.gravity_magnitude);
  o.static_init.gravity_magnitude = o.propagator.gravity_magnitude;
  read(c, s + "max_imu_gap_s", &o.propagator.max_gap_s);
  read(c, s + "imu_buffer_s", &o.propagator.buffer_s);
  read(c, s + "triangulation.min_depth", &o.triangulation.min_depth);
  read(c, s + "triangulation.max_depth", &o.triangulation.max_depth);
  read(c, s + "triangulation.max_condition", &o.triangulation.max_condition);
  read(c, s + "triangulation.max_iterations", &o.triangulation.max_iterations);
  std::string mode = "ground_truth";
  read(c, s + "init.mode", &mode);
  if (mode == "ground_truth") {
    o.init_mode = InitMode::kGroundTruth;
  } else if (mode == "static") {
    o.init_mode = InitMode::kStatic;
  } else {
    throw ConfigError(c.source() + ": " + s + "init.mode: expected ground_truth or static, got '" + mode + "'");
  }
  read(c, s + "init.window_s", &o.static_init.window_s);
  read(c, s + "init.max_accel_std", &o.static_init.max_accel_std);
  read(c, s + "init.sigma_theta_rp", &o.init_sigmas.theta_rp);
  read(c, s + "init.sigma_yaw", &o.init_sigmas.theta_yaw);
  read(c, s + "init.sigma_p", &o.init_sigmas.p);
  read(c, s + "init.sigma_v", &o.init_sigmas.v);
  read(c, s + "init.sigma_bg", &o.init_sigmas.bg);
  read(c, s + "init.sigma_ba", &o.init_sigmas.ba);
  read(c, s + "divergence.max_position_correction_m", &o.divergence.max_position_correction_m);
  read(c, s + "divergence.max_velocity_mps", &o.divergence.max_velocity_mps);

  // IMU noise: calibration file, overridable in the estimator section.
  ImuNoise& n = o.propagator.noise;
  read(calibration_cfg, "imu.gyroscope_noise_density", &n.sigma_w);
  read(calibration_cfg, "imu.gyroscope_random_walk", &n.sigma_wb);
  read(calibration_cfg, "imu.accelerometer_noise_density", &n.sigma_a);
  read(calibration_cfg, "imu.accelerometer_random_walk", &n.sigma_ab);
  read(c, s + "imu_noise.gyroscope_noise_density", &n.sigma_w);
  read(c, s + "imu_noise.gyroscope_random_walk", &n.sigma_wb);
  read(c, s + "imu_noise.accelerometer_noise_density", &n.sigma_a);
  read(c, s + "imu_noise.accelerometer_random_walk", &n.sigma_ab);
  read(c, s + "imu_gap_noise.gyroscope_noise_density", &o.propagator.gap_noise.sigma_w);
  read(c, s + "imu_gap_noise.accelerometer_noise_density", &o.propagator.gap_noise.sigma_a);

  if (!calibration_cfg.has("cameras.cam0")) {
    throw ConfigError(calibration_cfg.source() + ": cameras.cam0: missing (camera calibration required)");
  }
  o.cameras.push_back(camera_from_config(calibration_cfg.sub("cameras.cam0")));
  if (calibration_cfg.has("cameras.cam1")) o.cameras.push_back(camera_from_config(calibration_cfg.sub("cameras.cam1")));
  if (o.cameras.size() < 2) o.use_stereo = false;

  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.source() + ": " + s + e.what());
  }
  return o;
}

// ---------------------------------------------------------------- estimator
namespace {
std::vector<CameraInfo> make_cameras(const VioOptions& o) {
  o.validate();
  std::vector<CameraInfo> cams;
  for (const auto& c : o.cameras) cams.push_back(CameraInfo::from_calibration(c, o.sigma_px));
  return cams;
}
}  // namespace

VioEstimator::VioEstimator(const VioOptions& options)
    : options_(options),
      cameras_(make_cameras(options)),
      state_(std::make_unique<State>(options.state)),
      propagator_(options.propagator),
      msckf_(options.msckf, options.triangulation, cameras_),
      slam_(options.slam, options.triangulation, cameras_),
      static_init_(options.static_init) {}

ImuFeedStatus VioEstimator::feed_imu(const ImuData& imu) {
  const ImuFeedStatus status = propagator_.feed_imu(imu);
  if (!initialized_ && options_.init_mode == InitMode::kStatic &&
      (status == ImuFeedStatus::kAccepted || status == ImuFeedStatus::kAcceptedAfterGap)) {
    static_init_.feed_imu(imu);
    ImuValue x;
    int64_t t = 0;
    if (static_init_.try_initialize(&x, &t) == StaticInitStatus::kReady) initialize(x, t);
  }
  return status;
}

Matrix15d initial_covariance(const Eigen::Vector4d& q_GtoI, const InitSigmas& s) {
  Matrix15d P = Matrix15d::Zero();
  // Roll/pitch vs yaw: the orientation error is in the IMU frame; rotate the
  // G-frame diag(rp, rp, yaw) into it: P_θ = R_GtoI diag R_GtoIᵀ.
  const Eigen::Matrix3d R = quat_to_rot(quat_normalize(q_GtoI));
  const Eigen::Vector3d dg(s.theta_rp * s.theta_rp, s.theta_rp * s.theta_rp, s.theta_yaw * s.theta_yaw);
  P.block<3, 3>(0, 0) = R * dg.asDiagonal() * R.transpose();
  P.block<3, 3>(3, 3) = s.p * s.p * Eigen::Matrix3d::Identity();
  P.block<3, 3>(6, 6) = s.v * s.v * Eigen::Matrix3d::Identity();
  P.block<3, 3>(9, 9) = s.bg * s.bg * Eigen::Matrix3d::Identity();
  P.block<3, 3>(12, 12) = s.ba * s.ba * Eigen::Matrix3d::Identity();
  return P;
}

void VioEstimator::initialize(const ImuValue& value, int64_t utime) {
  initialize(value, utime, initial_covariance(value.q_GtoI, options_.init_sigmas));
}

void VioEstimator::initialize(const ImuValue& value, int64_t utime, const Matrix15d& P_imu) {
  if (!value.to_vector().allFinite() || !P_imu.allFinite()) {
    throw std::invalid_argument("VioEstimator::initialize: non-finite initial state or covariance");
  }
  state_ = std::make_unique<State>(options_.state);
  ImuValue v = value;
  v.q_GtoI = quat_normalize(value.q_GtoI);
  StateHelper::reset_imu(*state_, v, P_imu);
  state_->set_utime(utime);
  database_.clear();
  initialized_ = true;
  diverged_ = false;
}

void VioEstimator::restore(std::unique_ptr<State> state, FeatureDatabase tracks) {
  state_ = std::move(state);
  database_ = std::move(tracks);
  initialized_ = true;
  diverged_ = false;
}

void VioEstimator::reset() {
  state_ = std::make_unique<State>(options_.state);
  database_.clear();
  static_init_.clear();
  if (extension_) extension_->reset();
  initialized_ = false;
  diverged_ = false;
}

Matrix15d VioEstimator::imu_covariance() const {
  const int id = state_->imu()->id();
  return state_->cov().block<15, 15>(id, id);
}

ClonePoses VioEstimator::clone_poses() const { return estimator::clone_poses(*state_); }

void VioEstimator::report_divergence(const std::string& reason) {
  diverged_ = true;
  last_divergence_ = DivergenceReport{state_->utime(), reason};
  if (divergence_callback_) divergence_callback_(last_divergence_);
}

bool VioEstimator::check_health(const Eigen::Vector3d& p_before) {
  const State& st = *state_;
  const ImuValue x = st.imu()->get();
  std::ostringstream why;
  if (!x.to_vector().allFinite()) {
    why << "non-finite IMU state";
  } else if (!st.cov().allFinite()) {
    why << "non-finite covariance";
  } else if (st.cov().diagonal().minCoeff() < 0.0) {
    Eigen::Index i;
    const double d = st.cov().diagonal().minCoeff(&i);
    why << "negative covariance diagonal " << d << " at index " << i;
  } else if ((x.p_IinG - p_before).norm() > options_.divergence.max_position_correction_m) {
    why << "position correction of " << (x.p_IinG - p_before).norm() << " m in one frame (limit "
        << options_.divergence.max_position_correction_m << ")";
  } else if (x.v_IinG.norm() > options_.divergence.max_velocity_mps) {
    why << "speed " << x.v_IinG.norm() << " m/s (limit " << options_.divergence.max_velocity_mps << ")";
  } else {
    return true;
  }
  report_divergence(why.str());
  return false;
}

FrameStatus VioEstimator::feed_camera(const CameraFrame& frame) {
  if (diverged_) {
    ++frames_dropped_;
    return FrameStatus::kDiverged;
  }
  if (!initialized_) {
    ++frames_dropped_;
    return FrameStatus::kNotInitialized;
  }
  State& st = *state_;
  const bool first_at_init = st.clones().empty() && frame.utime == st.utime();
  if (frame.utime <= st.utime() && !first_at_init) {
    ++frames_dropped_;
    return FrameStatus::kRejectedOutOfOrder;
  }
  const Clock::time_point t_start = Clock::now();
  const double cpu_start = thread_cpu_ms();
  last_timing_ = FrameTiming{};
  if (first_at_init) {
    StateHelper::augment_clone(st, frame.utime);
    last_propagation_ = PropagationReport{};
    last_propagation_.ok = true;
  } else if (extension_ == nullptr) {
    last_propagation_ = propagator_.propagate_and_clone(st, frame.utime);
    if (!last_propagation_.ok) {
      ++frames_dropped_;
      return FrameStatus::kNoImu;
    }
  } else {
    last_propagation_ = propagator_.propagate(st, frame.utime, extension_);
    if (!last_propagation_.ok) {
      ++frames_dropped_;
      return FrameStatus::kNoImu;
    }
    StateHelper::augment_clone(st, frame.utime);
  }
  if (extension_) extension_->on_clone_added(st, frame.utime);
  last_timing_.propagate_ms = ms_since(t_start);
  try {
    process_frame(frame);
  } catch (const std::exception& e) {
    report_divergence(std::string("internal error: ") + e.what());
  }
  last_timing_.total_ms = ms_since(t_start);
  last_timing_.total_cpu_ms = thread_cpu_ms() - cpu_start;
  ++frames_processed_;
  return diverged_ ? FrameStatus::kDiverged : FrameStatus::kProcessed;
}

void VioEstimator::process_frame(const CameraFrame& frame) {
  State& st = *state_;
  const int64_t t = frame.utime;
  const Eigen::Vector3d p_before = st.imu()->get().p_IinG;
  UpdateStats stats;

  // Sort observations: landmarks in the state vs tracks in the database.
  std::map<int64_t, Feature> slam_now;
  std::vector<FeatureObservation> target_obs;
  const int num_cams = options_.use_stereo ? static_cast<int>(cameras_.size()) : 1;
  for (const auto& o : frame.observations) {
    if (o.is_target) {
      ++target_obs_ignored_;
      if (extension_ && o.camera_id >= 0 && o.camera_id < num_cams && o.normalized.allFinite()) {
        target_obs.push_back(o);
      }
      continue;
    }
    if (o.camera_id < 0 || o.camera_id >= num_cams || !o.normalized.allFinite()) {
      ++invalid_obs_;
      continue;
    }
    if (st.slam_features().count(o.feature_id) != 0) {
      Feature& f = slam_now[o.feature_id];
      f.feature_id = o.feature_id;
      auto& v = f.obs[o.camera_id];
      if (v.empty()) v.push_back(FeatureObs{t, o.normalized});
    } else {
      database_.add(t, o.feature_id, o.camera_id, o.normalized);
    }
  }

  // Tracks for the MSCKF and candidates for SLAM.
  std::vector<std::shared_ptr<Feature>> msckf_feats = database_.lost_before(t);
  std::vector<std::shared_ptr<Feature>> slam_init;
  const bool window_full = static_cast<int>(st.clones().size()) > st.options().max_clones;
  const int64_t marg_t = st.oldest_clone_utime();
  if (window_full) {
    std::vector<std::shared_ptr<Feature>> long_tracks;
    for (const auto& f : database_.observed_at(marg_t)) {
      if (f->last_utime() < t) continue;  // already in the lost set
      if (static_cast<int>(f->times().size()) >= st.options().max_clones) {
        long_tracks.push_back(f);
      } else {
        msckf_feats.push_back(f);
      }
    }
    std::sort(long_tracks.begin(), long_tracks.end(), by_track_length);
    const int slots = std::max(0, std::min(st.options().max_slam - static_cast<int>(st.slam_features().size()),
                                           options_.slam.max_init_per_frame));
    for (size_t i = 0; i < long_tracks.size(); ++i) {
      (static_cast<int>(i) < slots ? slam_init : msckf_feats).push_back(long_tracks[i]);
    }
  }

  Clock::time_point t0 = Clock::now();
  // Tracks above max_msckf_in_update stay in the database for the next
  // frame (their measurements were not used); the others are consumed.
  std::vector<std::shared_ptr<Feature>> deferred;
  msckf_.update(st, msckf_feats, &stats, &deferred);
  std::set<int64_t> deferred_ids;
  for (const auto& f : deferred) deferred_ids.insert(f->feature_id);
  for (const auto& f : msckf_feats) {
    if (deferred_ids.count(f->feature_id) == 0) database_.remove(f->feature_id);
  }
  last_timing_.msckf_ms = ms_since(t0);

  t0 = Clock::now();
  for (const auto& kv : st.slam_features()) {
    if (slam_now.count(kv.first) == 0) kv.second->should_marginalize = true;
  }
  slam_.update(st, slam_now, &stats);
  last_timing_.slam_update_ms = ms_since(t0);

  t0 = Clock::now();
  slam_.delayed_initialize(st, slam_init, &stats);
  for (const auto& f : slam_init) database_.remove(f->feature_id);
  last_timing_.slam_init_ms = ms_since(t0);

  // Extension update (target observations) after the static updates, before
  // the oldest clone leaves.
  if (extension_) extension_->update(st, t, target_obs);

  t0 = Clock::now();
  if (window_full) slam_.change_anchors(st, marg_t);
  stats.slam_marginalized = StateHelper::marginalize_flagged_slam(st);
  if (extension_) {
    const int n_leaving = static_cast<int>(st.clones().size()) - st.options().max_clones;
    auto it = st.clones().begin();
    for (int i = 0; i < n_leaving && it != st.clones().end(); ++i, ++it) extension_->on_clone_marginalized(st, it->first);
  }
  StateHelper::marginalize_old_clones(st);
  database_.clean_older_than(st.oldest_clone_utime());
  propagator_.clean_older_than(t);
  last_timing_.marginalize_ms = ms_since(t0);

  stats.slam_in_state = static_cast<int>(st.slam_features().size());
  last_stats_ = stats;
  total_stats_.accumulate(stats);
  check_health(p_before);
}

}  // namespace estimator
}  // namespace vimot

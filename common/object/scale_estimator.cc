#include "common/object/scale_estimator.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot::scale {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

template <typename T>
void read(const Config& c, const std::string& key, T* out) {
  if (c.has(key)) *out = c.get<T>(key);
}

bool finite4(const Eigen::Vector4d& v) { return v.allFinite(); }

}  // namespace

// ------------------------------------------------------------------ options

ScaleEstimatorOptions ScaleEstimatorOptions::from_config(const Config& cfg,
                                                         const std::string& section) {
  ScaleEstimatorOptions o;
  const std::string s = section.empty() ? "" : section + ".";
  if (!section.empty() && !cfg.has(section)) return o;  // whole section optional
  cfg.check_keys(section, {"window_size", "min_observations", "derivative_order", "motion_lowpass_s",
                           "motion_highpass_s", "epsilon_t1", "rho_t1", "rho_t2", "relative_condition_i",
                           "require_positive_scale", "max_gap_s", "quat_norm_tolerance"});
  read(cfg, s + "window_size", &o.window_size);
  read(cfg, s + "min_observations", &o.min_observations);
  read(cfg, s + "derivative_order", &o.derivative_order);
  read(cfg, s + "motion_lowpass_s", &o.motion_lowpass_s);
  read(cfg, s + "motion_highpass_s", &o.motion_highpass_s);
  read(cfg, s + "epsilon_t1", &o.epsilon_t1);
  read(cfg, s + "rho_t1", &o.rho_t1);
  read(cfg, s + "rho_t2", &o.rho_t2);
  read(cfg, s + "relative_condition_i", &o.relative_condition_i);
  read(cfg, s + "require_positive_scale", &o.require_positive_scale);
  read(cfg, s + "max_gap_s", &o.max_gap_s);
  read(cfg, s + "quat_norm_tolerance", &o.quat_norm_tolerance);
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError("config '" + cfg.source() + "': " + s + e.what());
  }
  return o;
}

void ScaleEstimatorOptions::validate() const {
  auto fail = [](const std::string& key, const std::string& what) {
    throw std::invalid_argument(key + " " + what);
  };
  if (derivative_order != 1 && derivative_order != 2) fail("derivative_order", "must be 1 or 2");
  if (!(motion_lowpass_s >= 0.0) || !std::isfinite(motion_lowpass_s)) fail("motion_lowpass_s", "must be finite and >= 0");
  if (!(motion_highpass_s >= 0.0) || !std::isfinite(motion_highpass_s))
    fail("motion_highpass_s", "must be finite and >= 0");
  if (motion_highpass_s > 0.0 && !(motion_highpass_s > motion_lowpass_s))
    fail("motion_highpass_s", "must exceed motion_lowpass_s (else the band is empty)");
  if (min_observations < 4) fail("min_observations", "must be >= 4");
  if (window_size < min_observations) fail("window_size", "must be >= min_observations");
  if (!(epsilon_t1 >= 0.0) || !std::isfinite(epsilon_t1)) fail("epsilon_t1", "must be finite and >= 0");
  if (!(rho_t1 >= 0.0) || !std::isfinite(rho_t1)) fail("rho_t1", "must be finite and >= 0");
  if (!(rho_t2 >= 0.0) || !std::isfinite(rho_t2)) fail("rho_t2", "must be finite and >= 0");
  if (!std::isfinite(max_gap_s)) fail("max_gap_s", "must be finite");
  if (!(quat_norm_tolerance > 0.0) || !(quat_norm_tolerance < 1.0))
    fail("quat_norm_tolerance", "must be in (0, 1)");
}

// ------------------------------------------------------------- observation

ScaleObservation ScaleObservation::from_rotations(int64_t utime, const Eigen::Matrix3d& R_CtoG,
                                                  const Eigen::Vector3d& p_CinG,
                                                  const Eigen::Matrix3d& R_OtoC,
                                                  const Eigen::Vector3d& pbar_OinC) {
  ScaleObservation o;
  o.utime = utime;
  o.q_GtoC = rot_to_quat(R_CtoG.transpose());
  o.p_CinG = p_CinG;
  o.q_OtoC = rot_to_quat(R_OtoC);
  o.pbar_OinC = pbar_OinC;
  return o;
}

Eigen::Matrix3d ScaleObservation::R_CtoG() const { return quat_to_rot(q_GtoC).transpose(); }

Eigen::Vector3d ScaleObservation::p_d_in_G() const { return R_CtoG() * pbar_OinC; }

const char* to_string(AddStatus status) {
  switch (status) {
    case AddStatus::kAdded: return "added";
    case AddStatus::kAddedAfterGap: return "added_after_gap";
    case AddStatus::kRejectedNonFinite: return "rejected_non_finite";
    case AddStatus::kRejectedBadQuaternion: return "rejected_bad_quaternion";
    case AddStatus::kRejectedDuplicateTime: return "rejected_duplicate_time";
    case AddStatus::kRejectedTimeBackwards: return "rejected_time_backwards";
  }
  return "unknown";
}

const char* to_string(ScaleStatus status) {
  switch (status) {
    case ScaleStatus::kInsufficientData: return "insufficient_data";
    case ScaleStatus::kRejected: return "rejected";
    case ScaleStatus::kAccepted: return "accepted";
  }
  return "unknown";
}

// --------------------------------------------------------------- equations

std::vector<Eigen::Vector3d> central_difference(const std::vector<int64_t>& utimes,
                                                const std::vector<Eigen::Vector3d>& values,
                                                int n) {
  if (n != 1 && n != 2) throw std::invalid_argument("central_difference: n must be 1 or 2");
  if (utimes.size() != values.size())
    throw std::invalid_argument("central_difference: utimes and values differ in size");
  std::vector<Eigen::Vector3d> out;
  if (utimes.size() < 3) return out;
  out.reserve(utimes.size() - 2);
  for (size_t k = 1; k + 1 < utimes.size(); ++k) {
    // Integer differences first: exact, no loss from large absolute utimes.
    const int64_t d1 = utimes[k] - utimes[k - 1];
    const int64_t d2 = utimes[k + 1] - utimes[k];
    if (d1 <= 0 || d2 <= 0)
      throw std::invalid_argument("central_difference: utimes must be strictly increasing");
    const double h1 = 1e-6 * static_cast<double>(d1);
    const double h2 = 1e-6 * static_cast<double>(d2);
    const double h = h1 + h2;
    double wm, w0, wp;  // weights of values[k-1], values[k], values[k+1]
    if (n == 1) {
      wm = -h2 / (h1 * h);
      w0 = (h2 - h1) / (h1 * h2);
      wp = h1 / (h2 * h);
    } else {
      wm = 2.0 / (h1 * h);
      w0 = -2.0 / (h1 * h2);
      wp = 2.0 / (h2 * h);
    }
    out.push_back(wm * values[k - 1] + w0 * values[k] + wp * values[k + 1]);
  }
  return out;
}

std::vector<Eigen::Vector3d> band_pass(const std::vector<int64_t>& utimes, const std::vector<Eigen::Vector3d>& m,
                                       double lowpass_s, double highpass_s) {
  if (utimes.size() != m.size()) throw std::invalid_argument("band_pass: utimes and samples differ in size");
  if (!(lowpass_s >= 0.0) || !(highpass_s >= 0.0)) throw std::invalid_argument("band_pass: negative width");
  if (lowpass_s == 0.0 && highpass_s == 0.0) return m;
  // Half widths in µs; integer time arithmetic, as central_difference.
  const auto half_us = [](double w) { return static_cast<int64_t>(std::llround(0.5e6 * w)); };
  const int64_t hl = half_us(lowpass_s), hh = half_us(highpass_s), reach = std::max(hl, hh);
  // Running sum of m over [t_k - h, t_k + h] with two monotone indices.
  struct Box {
    int64_t half;
    size_t lo{0}, hi{0};
    Eigen::Vector3d sum{Eigen::Vector3d::Zero()};
    Eigen::Vector3d mean_at(size_t k, const std::vector<int64_t>& t, const std::vector<Eigen::Vector3d>& x) {
      while (hi < t.size() && t[hi] <= t[k] + half) sum += x[hi++];
      while (t[lo] < t[k] - half) sum -= x[lo++];
      return sum / static_cast<double>(hi - lo);
    }
  };
  Box low{hl}, high{hh};
  std::vector<Eigen::Vector3d> out;
  for (size_t k = 0; k < m.size(); ++k) {
    if (utimes[k] - utimes.front() < reach || utimes.back() - utimes[k] < reach) continue;
    const Eigen::Vector3d smooth = hl > 0 ? low.mean_at(k, utimes, m) : m[k];
    out.push_back(hh > 0 ? Eigen::Vector3d(smooth - high.mean_at(k, utimes, m)) : smooth);
  }
  return out;
}

ScaleResult estimate_scale(const std::vector<Eigen::Vector3d>& m_c,
                           const std::vector<Eigen::Vector3d>& m_d,
                           const ScaleEstimatorOptions& options) {
  if (m_c.size() != m_d.size())
    throw std::invalid_argument("estimate_scale: m_c and m_d differ in size");
  ScaleResult r;
  const size_t M = m_c.size();
  r.num_motion_samples = static_cast<int>(M);
  r.num_observations = static_cast<int>(M + 2);
  if (M < 2) return r;  // kInsufficientData: no sample covariance

  // Eq. 12: sample means and unbiased (1/(M-1)) covariances.
  Eigen::Vector3d mean_c = Eigen::Vector3d::Zero(), mean_d = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < M; ++k) {
    mean_c += m_c[k];
    mean_d += m_d[k];
  }
  mean_c /= static_cast<double>(M);
  mean_d /= static_cast<double>(M);
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero(), C = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < M; ++k) {
    const Eigen::Vector3d dc = m_c[k] - mean_c;
    const Eigen::Vector3d dd = m_d[k] - mean_d;
    D += dd * dc.transpose();  // D_ij = Cov(m_d^i, m_c^j)
    C += dc * dc.transpose();  // C_ij = Cov(m_c^i, m_c^j)
  }
  D /= static_cast<double>(M - 1);
  C /= static_cast<double>(M - 1);
  r.cov_dc = D;
  r.cov_cc = C;

  const double sum_d2 = D.squaredNorm();          // sum_ij Cov^2(m_d^i, m_c^j)
  const double sum_c2 = C.squaredNorm();          // sum_ij Cov^2(m_c^i, m_c^j)
  const double sum_dc = D.cwiseProduct(C).sum();  // sum_ij Cov(m_d^i,m_c^j) Cov(m_c^i,m_c^j)

  // Eq. 14. With sum_d2 == 0, f is constant (= sum_c2): s* undefined.
  if (sum_d2 > 0.0 && std::isfinite(sum_d2)) {
    r.scale = -sum_dc / sum_d2;
    // Eq. 13 evaluated as the sum of squares (no cancellation of the
    // expanded quadratic): f(s*) = sum_ij (s* D_ij + C_ij)^2.
    r.f_value = (r.scale * D + C).squaredNorm();
  } else {
    r.scale = kNaN;
    r.f_value = sum_c2;
  }
  r.f_relative = sum_c2 > 0.0 ? r.f_value / sum_c2 : 0.0;

  // Eq. 19.
  r.condition[0] = options.relative_condition_i ? r.f_relative : r.f_value;
  r.condition[1] = sum_c2;
  r.condition[2] = sum_d2;
  r.condition_ok[0] = r.condition[0] <= options.epsilon_t1;
  r.condition_ok[1] = r.condition[1] >= options.rho_t1;
  r.condition_ok[2] = r.condition[2] >= options.rho_t2;
  r.scale_positive_ok = std::isfinite(r.scale) && r.scale > 0.0;
  r.failed_condition = 0;
  for (int i = 0; i < 3; ++i) {
    if (!r.condition_ok[i]) {
      r.failed_condition = i + 1;
      break;
    }
  }
  if (r.failed_condition == 0 && options.require_positive_scale && !r.scale_positive_ok)
    r.failed_condition = 4;
  // A NaN scale can only pass with require_positive_scale off and
  // rho_t2 == 0; never accept it.
  r.accepted = r.failed_condition == 0 && std::isfinite(r.scale);
  r.status = r.accepted ? ScaleStatus::kAccepted : ScaleStatus::kRejected;
  return r;
}

ObjectPoseInWorld object_pose_in_world(double scale, const ScaleObservation& obs) {
  ObjectPoseInWorld p;
  p.utime = obs.utime;
  p.scale = scale;
  const Eigen::Matrix3d R_CtoG = obs.R_CtoG();
  p.p_OinC = scale * obs.pbar_OinC;                       // Eq. 20
  p.R_OtoG = R_CtoG * quat_to_rot(obs.q_OtoC);            // Eq. 21
  p.q_GtoO = quat_multiply(quat_inverse(obs.q_OtoC), obs.q_GtoC);  // R_CtoO R_GtoC
  p.p_OinG = R_CtoG * p.p_OinC + obs.p_CinG;              // Eq. 21
  return p;
}

// --------------------------------------------------------------- estimator

ScaleEstimator::ScaleEstimator(const ScaleEstimatorOptions& options) : options_(options) {
  options_.validate();
}

AddStatus ScaleEstimator::add(const ScaleObservation& in) {
  if (!finite4(in.q_GtoC) || !finite4(in.q_OtoC) || !in.p_CinG.allFinite() ||
      !in.pbar_OinC.allFinite()) {
    ++stats_.rejected_non_finite;
    return AddStatus::kRejectedNonFinite;
  }
  if (std::abs(in.q_GtoC.norm() - 1.0) > options_.quat_norm_tolerance ||
      std::abs(in.q_OtoC.norm() - 1.0) > options_.quat_norm_tolerance) {
    ++stats_.rejected_bad_quaternion;
    return AddStatus::kRejectedBadQuaternion;
  }
  if (last_utime_) {
    if (in.utime == *last_utime_) {
      ++stats_.rejected_duplicate_time;
      return AddStatus::kRejectedDuplicateTime;
    }
    if (in.utime < *last_utime_) {
      ++stats_.rejected_time_backwards;
      return AddStatus::kRejectedTimeBackwards;
    }
  }
  AddStatus status = AddStatus::kAdded;
  if (options_.max_gap_s > 0.0 && !window_.empty() &&
      1e-6 * static_cast<double>(in.utime - window_.back().utime) > options_.max_gap_s) {
    window_.clear();
    ++stats_.gap_resets;
    status = AddStatus::kAddedAfterGap;
  }
  ScaleObservation o = in;
  o.q_GtoC = quat_normalize(in.q_GtoC);
  o.q_OtoC = quat_normalize(in.q_OtoC);
  window_.push_back(o);
  while (static_cast<int>(window_.size()) > options_.window_size) window_.pop_front();
  last_utime_ = in.utime;
  ++stats_.added;
  return status;
}

ScaleResult ScaleEstimator::update() {
  ScaleResult r;
  const int N = static_cast<int>(window_.size());
  if (N >= options_.min_observations) {
    std::vector<int64_t> t;
    std::vector<Eigen::Vector3d> p_c, p_d;
    t.reserve(N);
    p_c.reserve(N);
    p_d.reserve(N);
    for (const ScaleObservation& o : window_) {
      t.push_back(o.utime);
      p_c.push_back(o.p_CinG);
      p_d.push_back(o.p_d_in_G());  // Eq. 5
    }
    // Eq. 8-9 at the interior samples t[1 .. N-2], then the band-pass.
    const std::vector<int64_t> t_motion(t.begin() + 1, t.end() - 1);
    const auto m_c = band_pass(t_motion, central_difference(t, p_c, options_.derivative_order),
                               options_.motion_lowpass_s, options_.motion_highpass_s);
    const auto m_d = band_pass(t_motion, central_difference(t, p_d, options_.derivative_order),
                               options_.motion_lowpass_s, options_.motion_highpass_s);
    r = estimate_scale(m_c, m_d, options_);
  }
  r.num_observations = N;
  r.utime = window_.empty() ? 0 : window_.back().utime;
  last_result_ = r;
  if (r.accepted) accepted_ = r;
  return r;
}

std::optional<ScaleResult> ScaleEstimator::add_and_update(const ScaleObservation& obs,
                                                          AddStatus* status) {
  const AddStatus s = add(obs);
  if (status) *status = s;
  if (!is_added(s)) return std::nullopt;
  return update();
}

double ScaleEstimator::scale() const { return accepted_ ? accepted_->scale : kNaN; }

std::optional<ObjectPoseInWorld> ScaleEstimator::latest_object_pose() const {
  if (!accepted_ || window_.empty()) return std::nullopt;
  return object_pose_in_world(accepted_->scale, window_.back());
}

std::optional<ObjectPoseInWorld> ScaleEstimator::object_pose(const ScaleObservation& obs) const {
  if (!accepted_) return std::nullopt;
  if (!finite4(obs.q_GtoC) || !finite4(obs.q_OtoC) || !obs.p_CinG.allFinite() ||
      !obs.pbar_OinC.allFinite())
    return std::nullopt;
  if (std::abs(obs.q_GtoC.norm() - 1.0) > options_.quat_norm_tolerance ||
      std::abs(obs.q_OtoC.norm() - 1.0) > options_.quat_norm_tolerance)
    return std::nullopt;
  ScaleObservation o = obs;
  o.q_GtoC = quat_normalize(obs.q_GtoC);
  o.q_OtoC = quat_normalize(obs.q_OtoC);
  return object_pose_in_world(accepted_->scale, o);
}

void ScaleEstimator::clear_window() { window_.clear(); }

void ScaleEstimator::reset() {
  window_.clear();
  last_utime_.reset();
  accepted_.reset();
  last_result_ = ScaleResult();
}

}  // namespace vimot::scale

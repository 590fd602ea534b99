#include "common/target/adaptive_noise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "common/estimator/chi_square.h"

namespace vimot {
namespace target {

void AdaptiveNoiseOptions::validate() const {
  if (window < 2) throw std::invalid_argument("adaptive: window must be >= 2, got " + std::to_string(window));
  if (!(sigma_min > 0.0) || !(sigma_max >= sigma_min) || !std::isfinite(sigma_max)) {
    throw std::invalid_argument("adaptive: need 0 < sigma_min <= sigma_max < inf");
  }
  if (!(nis_max > 1.0)) throw std::invalid_argument("adaptive: nis_max must be > 1");
  if (!(max_step > 1.0) || !std::isfinite(max_step)) throw std::invalid_argument("adaptive: max_step must be > 1");
  if (!(hold_s >= 0.0) || !std::isfinite(hold_s)) throw std::invalid_argument("adaptive: hold_s must be >= 0");
  if (horizon < 1 || horizon > window) {
    throw std::invalid_argument("adaptive: horizon must be in [1, window], got " + std::to_string(horizon));
  }
}

AdaptiveNoise::AdaptiveNoise(const AdaptiveNoiseOptions& options, double sigma0) : options_(options) {
  options_.validate();
  sigma_ = std::clamp(sigma0, options_.sigma_min, options_.sigma_max);
  matched_ = sigma_;
}

void AdaptiveNoise::add_innovation(double chi2, int dof) {
  if (dof <= 0 || !std::isfinite(chi2)) return;
  frame_chi2_ += chi2;
  frame_dof_ += dof;
}

double AdaptiveNoise::window_nis() const {
  double chi2 = 0.0;
  int dof = 0;
  for (const Frame& f : window_) {
    chi2 += f.chi2;
    dof += f.dof;
  }
  return dof > 0 ? chi2 / dof : 0.0;
}

void AdaptiveNoise::end_frame(const Eigen::VectorXd& x_minus, const Eigen::VectorXd& P_minus,
                              const Eigen::VectorXd& x_plus, const Eigen::VectorXd& P_plus, double dt) {
  const Eigen::Index n = x_minus.size();
  if (x_plus.size() != n || P_minus.size() != n || P_plus.size() != n || !(dt > 0.0) || n < 1 ||
      n > kMaxComponents) {
    throw std::invalid_argument("AdaptiveNoise::end_frame: sizes differ, not 1.." +
                                std::to_string(kMaxComponents) + ", or dt <= 0");
  }
  Frame f;
  const double q_used = sigma_ * sigma_ * dt;
  for (Eigen::Index j = 0; j < n; ++j) {
    f.dx[static_cast<size_t>(j)] = x_plus(j) - x_minus(j);
    f.c_sum += q_used - (P_minus(j) - P_plus(j));
  }
  f.components = static_cast<int>(n);
  f.dt = dt;
  finish(f);
}

void AdaptiveNoise::end_frame_innovations_only(double dt) {
  Frame f;
  f.dt = std::max(dt, 0.0);
  finish(f);
}

bool AdaptiveNoise::window_density(double* q_density) const {
  const int h = options_.horizon;
  double q = 0.0, unit = 0.0;
  // Every run of h consecutive matching frames (a frame without matching
  // breaks the run: its correction is not in the sum).
  for (size_t end = 0; end < window_.size(); ++end) {
    if (end + 1 < static_cast<size_t>(h)) continue;
    const size_t begin = end + 1 - static_cast<size_t>(h);
    const int n = window_[begin].components;
    std::array<double, kMaxComponents> dx_sum{};
    double c = 0.0, dt = 0.0;
    bool complete = n > 0;
    for (size_t i = begin; complete && i <= end; ++i) {
      const Frame& f = window_[i];
      complete = f.components == n;
      for (int j = 0; j < n; ++j) dx_sum[static_cast<size_t>(j)] += f.dx[static_cast<size_t>(j)];
      c += f.c_sum;
      dt += f.dt;
    }
    if (!complete) continue;
    for (int j = 0; j < n; ++j) q += dx_sum[static_cast<size_t>(j)] * dx_sum[static_cast<size_t>(j)];
    q += c;
    unit += n * dt;
  }
  if (!(unit > 0.0)) return false;
  *q_density = q / unit;
  return true;
}

bool AdaptiveNoise::violates(double chi2, int dof) const {
  return dof > 0 && chi2 > options_.nis_max * estimator::chi2_quantile(0.99, dof);
}

void AdaptiveNoise::violate(double nis, double dt) {
  ++violations_;
  // How long the rejected σ has been used: the window (its evidence) and
  // this frame, counted once however many steps the frame takes.
  if (frame_tau_ == 0.0) {
    frame_tau_ = dt;
    for (const Frame& w : window_) frame_tau_ += w.dt;
  }
  window_.clear();
  frames_since_violation_ = 0;
  consistent_ = false;
  const double old_sigma = sigma_;
  sigma_ = std::min(options_.sigma_max, sigma_ * std::sqrt(std::min(nis, options_.max_step)));
  inflation_ = (sigma_ * sigma_ - old_sigma * old_sigma) * frame_tau_;
  inflation_time_ = frame_tau_;
}

bool AdaptiveNoise::inflate_before_update(double chi2, int dof, double dt) {
  inflation_ = 0.0;
  inflation_time_ = 0.0;
  // Once the frame violated, step on until its blocks are where the gate
  // accepts them: stopping at the violation bound would leave them between
  // it and the gate, rejected, and the target drifting without a violation.
  const bool stepping = frame_tau_ > 0.0;
  const bool step = stepping ? dof > 0 && chi2 > estimator::chi2_quantile(0.95, dof) : violates(chi2, dof);
  if (!step || !(dt > 0.0) || sigma_ >= options_.sigma_max) return false;
  violate(chi2 / dof, dt);
  return true;
}

void AdaptiveNoise::finish(Frame f) {
  f.chi2 = frame_chi2_;
  f.dof = frame_dof_;
  frame_chi2_ = 0.0;
  frame_dof_ = 0;
  inflation_ = 0.0;
  inflation_time_ = 0.0;
  time_ += f.dt;
  const bool violated = violates(f.chi2, f.dof);
  if (violated) violate(f.chi2 / f.dof, f.dt);
  frame_tau_ = 0.0;
  if (violated) return;
  window_.push_back(f);
  while (static_cast<int>(window_.size()) > options_.window) window_.pop_front();
  ++frames_since_violation_;
  double q_density = 0.0;
  // Half a window of evidence before σ̂ replaces the current value.
  if (f.components > 0 && 2 * static_cast<int>(window_.size()) >= options_.window && window_density(&q_density)) {
    matched_ = std::clamp(std::sqrt(std::max(q_density, 0.0)), options_.sigma_min, options_.sigma_max);
    while (!recent_.empty() && recent_.front().first < time_ - options_.hold_s) recent_.pop_front();
    while (!recent_.empty() && recent_.back().second <= matched_) recent_.pop_back();  // never the max again
    recent_.emplace_back(time_, matched_);
    sigma_ = recent_.front().second;
  }
  consistent_ = frames_since_violation_ >= options_.window && window_nis() <= options_.nis_max;
}

void AdaptiveNoise::save(estimator::CheckpointWriter* out) const {
  out->put(sigma_);
  out->put(matched_);
  out->put(time_);
  out->put(static_cast<int64_t>(recent_.size()));
  for (const auto& [time, sigma] : recent_) {
    out->put(time);
    out->put(sigma);
  }
  out->put(static_cast<int64_t>(window_.size()));
  for (const Frame& f : window_) out->put(f);
  out->put(frame_chi2_);
  out->put(frame_dof_);
  out->put(frames_since_violation_);
  out->put(consistent_);
  out->put(violations_);
  out->put(inflation_);
  out->put(inflation_time_);
  // frame_tau_ is 0 between frames, where checkpoints are taken.
}

bool AdaptiveNoise::load(estimator::CheckpointReader* in) {
  AdaptiveNoise a = *this;
  a.sigma_ = in->take<double>();
  a.matched_ = in->take<double>();
  a.time_ = in->take<double>();
  const int64_t r = in->take<int64_t>();
  if (r < 0 || static_cast<uint64_t>(r) > in->left() / (2 * sizeof(double))) return false;
  a.recent_.clear();
  for (int64_t i = 0; i < r; ++i) {
    const double time = in->take<double>();
    a.recent_.emplace_back(time, in->take<double>());
  }
  const int64_t n = in->take<int64_t>();
  if (n < 0 || n > options_.window) return false;
  a.window_.clear();
  for (int64_t i = 0; i < n; ++i) {
    a.window_.push_back(in->take<Frame>());
    if (a.window_.back().components < 0 || a.window_.back().components > kMaxComponents) return false;
  }
  a.frame_chi2_ = in->take<double>();
  a.frame_dof_ = in->take<int>();
  a.frames_since_violation_ = in->take<int>();
  a.consistent_ = in->take<bool>();
  a.violations_ = in->take<int64_t>();
  a.inflation_ = in->take<double>();
  a.inflation_time_ = in->take<double>();
  a.frame_tau_ = 0.0;
  if (!in->ok() || !(a.sigma_ > 0.0)) return false;
  *this = std::move(a);
  return true;
}

}  // namespace target
}  // namespace vimot

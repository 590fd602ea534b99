#include "common/process/stream_guard.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace vimot {

void StreamGuardOptions::validate() const {
  if (!(expected_period_s >= 0.0) || !std::isfinite(expected_period_s)) {
    throw std::invalid_argument("rate_hz: must be finite and >= 0");
  }
  if (!(max_forward_jump_s > 0.0)) throw std::invalid_argument("max_forward_jump_s: must be > 0");
  if (!(max_backward_jump_s > 0.0)) throw std::invalid_argument("max_backward_jump_s: must be > 0");
  if (reset_after < 1) throw std::invalid_argument("source_reset_after: must be >= 1");
  if (!(max_outage_s >= max_forward_jump_s)) throw std::invalid_argument("max_outage_s: must be >= max_forward_jump_s");
}

StreamGuard::StreamGuard(std::string name, const StreamGuardOptions& options)
    : name_(std::move(name)), options_(options) {
  options_.validate();
}

void StreamGuard::reset() {
  has_last_ = false;
  suspects_ = 0;
}

int64_t StreamGuard::count_outage(double step_s, StreamCheck* out) {
  const int64_t rejected_in_gap = std::exchange(rejected_since_accept_, 0);
  if (!(step_s > 0.0 && step_s <= options_.max_outage_s && options_.expected_period_s > 0.0)) return 0;
  out->lost = std::max<int64_t>(0, std::llround(step_s / options_.expected_period_s) - 1 - rejected_in_gap);
  lost_ += out->lost;
  return out->lost;
}

StreamCheck StreamGuard::check(int64_t utime) {
  StreamCheck out;
  if (!has_last_) {
    // After reset() (another stream's source reset): a step forward from
    // the old clock is an outage of this stream too, counted as lost.
    if (has_old_ && count_outage(1e-6 * static_cast<double>(utime - last_), &out) > 0) {
      out.message = std::to_string(out.lost) + " " + name_ + " message(s) lost before utime " +
                    std::to_string(utime) + " (across a source reset)";
    }
    has_last_ = has_old_ = true;
    last_ = utime;
    return out;
  }
  const double step_s = 1e-6 * static_cast<double>(utime - last_);
  if (step_s > options_.max_forward_jump_s || step_s < -options_.max_backward_jump_s) {
    // A new clock is believed once it has been seen consistently: each
    // suspect message within the forward bound after the previous one.
    const double from_suspect_s = 1e-6 * static_cast<double>(utime - last_suspect_);
    const bool consistent = suspects_ > 0 && from_suspect_s > 0.0 && from_suspect_s <= options_.max_forward_jump_s;
    suspects_ = consistent ? suspects_ + 1 : 1;
    last_suspect_ = utime;
    if (suspects_ >= options_.reset_after) {
      ++source_resets_;
      suspects_ = 0;
      last_ = utime;
      out.verdict = StreamVerdict::kSourceReset;
      out.message = name_ + " clock moved by " + std::to_string(step_s) + " s and stayed there: source reset at utime " +
                    std::to_string(utime);
      if (count_outage(step_s, &out) > 0) out.message += " (an outage: " + std::to_string(out.lost) + " message(s) lost)";
      return out;
    }
    ++rejected_;
    ++rejected_since_accept_;
    out.verdict = StreamVerdict::kRejectJump;
    out.message = name_ + " at utime " + std::to_string(utime) + " jumps " + std::to_string(step_s) +
                  " s from the stream's clock (limits +" + std::to_string(options_.max_forward_jump_s) + " / -" +
                  std::to_string(options_.max_backward_jump_s) + " s)";
    return out;
  }
  suspects_ = 0;
  if (step_s <= 0.0) return out;
  // A rejected message (a bad stamp on a sample that did arrive) took one of
  // the gap's slots: it is counted as rejected, not again as lost.
  if (step_s <= 1.5 * options_.expected_period_s) {
    rejected_since_accept_ = 0;  // jitter, not a gap
  } else if (count_outage(step_s, &out) > 0) {
    out.message = std::to_string(out.lost) + " " + name_ + " message(s) lost before utime " + std::to_string(utime) +
                  " (gap " + std::to_string(step_s) + " s)";
  }
  last_ = utime;
  return out;
}

}  // namespace vimot

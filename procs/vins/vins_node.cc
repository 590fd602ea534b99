#include "procs/vins/vins_node.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "common/estimator/checkpoint.h"
#include "common/estimator/initial_estimate.h"
#include "common/estimator/nav_state_of.h"
#include "common/estimator/vins_config.h"

namespace vimot {

void InputGuardOptions::validate() const {
  for (const StreamGuardOptions* s : {&imu, &features, &ground_truth}) s->validate();
  if (!(max_gyro_radps > 0.0)) throw std::invalid_argument("max_gyro_radps: must be > 0");
  if (!(max_accel_mps2 > 0.0)) throw std::invalid_argument("max_accel_mps2: must be > 0");
  if (!(max_normalized > 0.0)) throw std::invalid_argument("max_normalized: must be > 0");
  if (!(max_pixels_outside >= 0.0)) throw std::invalid_argument("max_pixels_outside: must be >= 0");
  if (!(max_imu_gap_s > 0.0)) throw std::invalid_argument("max_imu_gap_s: must be > 0");
  if (!(bridge_max_gap_s >= 0.0)) throw std::invalid_argument("bridge_max_gap_s: must be >= 0");
  if (max_rejected_frames < 1) throw std::invalid_argument("max_rejected_frames: must be >= 1");
  if (consistency_window < 1) throw std::invalid_argument("consistency_window: must be >= 1");
  if (consistency_min_tests < 1) throw std::invalid_argument("consistency_min_tests: must be >= 1");
  if (!(max_chi2_failure_fraction > 0.0 && max_chi2_failure_fraction <= 1.0)) {
    throw std::invalid_argument("max_chi2_failure_fraction: must be in (0, 1]");
  }
  if (!(max_quat_norm_error >= 0.0 && max_quat_norm_error < 1.0)) {
    throw std::invalid_argument("max_quat_norm_error: must be in [0, 1)");
  }
}

InputGuardOptions input_guard_options_from_config(const Config& cfg) {
  InputGuardOptions o;
  if (!cfg.has("input")) return o;
  cfg.check_keys("input", {"imu", "features", "ground_truth", "source_reset_after", "max_gyro_radps",
                           "max_accel_mps2", "max_normalized", "max_pixels_outside", "max_imu_gap_s", "bridge_max_gap_s",
                           "max_rejected_frames", "consistency_window",
                           "consistency_min_tests", "max_chi2_failure_fraction", "max_quat_norm_error"});
  const int reset_after = cfg.get_or<int>("input.source_reset_after", o.imu.reset_after);
  const std::pair<const char*, StreamGuardOptions*> streams[] = {
      {"imu", &o.imu}, {"features", &o.features}, {"ground_truth", &o.ground_truth}};
  for (const auto& [name, s] : streams) {
    const std::string k = std::string("input.") + name;
    cfg.check_keys(k, {"rate_hz", "max_forward_jump_s", "max_backward_jump_s", "max_outage_s"});
    const double rate = cfg.get_or<double>(k + ".rate_hz", 0.0);
    if (!(rate >= 0.0) || !std::isfinite(rate)) cfg.fail(k + ".rate_hz", "must be finite and >= 0");
    s->expected_period_s = rate > 0.0 ? 1.0 / rate : 0.0;
    s->max_forward_jump_s = cfg.get_or<double>(k + ".max_forward_jump_s", s->max_forward_jump_s);
    s->max_backward_jump_s = cfg.get_or<double>(k + ".max_backward_jump_s", s->max_backward_jump_s);
    s->max_outage_s = cfg.get_or<double>(k + ".max_outage_s", s->max_outage_s);
    s->reset_after = reset_after;
  }
  o.max_gyro_radps = cfg.get_or<double>("input.max_gyro_radps", o.max_gyro_radps);
  o.max_accel_mps2 = cfg.get_or<double>("input.max_accel_mps2", o.max_accel_mps2);
  o.max_normalized = cfg.get_or<double>("input.max_normalized", o.max_normalized);
  o.max_pixels_outside = cfg.get_or<double>("input.max_pixels_outside", o.max_pixels_outside);
  o.max_imu_gap_s = cfg.get_or<double>("input.max_imu_gap_s", o.max_imu_gap_s);
  o.bridge_max_gap_s = cfg.get_or<double>("input.bridge_max_gap_s", o.bridge_max_gap_s);
  o.max_rejected_frames = cfg.get_or<int>("input.max_rejected_frames", o.max_rejected_frames);
  o.consistency_window = cfg.get_or<int>("input.consistency_window", o.consistency_window);
  o.consistency_min_tests = cfg.get_or<int>("input.consistency_min_tests", o.consistency_min_tests);
  o.max_chi2_failure_fraction = cfg.get_or<double>("input.max_chi2_failure_fraction", o.max_chi2_failure_fraction);
  o.max_quat_norm_error = cfg.get_or<double>("input.max_quat_norm_error", o.max_quat_norm_error);
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError(cfg.source() + ": input." + e.what());
  }
  return o;
}

bool validate_quaternion(Eigen::Vector4d* q, double max_norm_error, std::string* why) {
  const double n = q->norm();
  if (!std::isfinite(n) || std::abs(n - 1.0) > max_norm_error) {
    std::ostringstream msg;
    msg << "quaternion norm " << n << " is not 1 (tolerance " << max_norm_error << ")";
    *why = msg.str();
    return false;
  }
  *q /= n;
  return true;
}

VinsNodeOptions vins_node_options_from_config(const Config& cfg) {
  cfg.check_keys("", estimator::vins_config_keys());
  cfg.check_keys("output", {"imu_rate", "imu_rate_every"});
  VinsNodeOptions options;
  options.vio = estimator::vio_options_from_config(cfg);
  const estimator::VinsStartOptions start = estimator::start_options_from_config(cfg);
  options.init_from_ground_truth = start.mode == estimator::InitMode::kGroundTruth;
  options.perturb_seed = start.perturb_seed;
  options.publish_imu_rate = cfg.get_or<bool>("output.imu_rate", options.publish_imu_rate);
  options.imu_rate_every = cfg.get_or<int>("output.imu_rate_every", options.imu_rate_every);
  if (options.imu_rate_every < 1) cfg.fail("output.imu_rate_every", "must be >= 1");
  options.input = input_guard_options_from_config(cfg);
  check_bridge_options(options.input, options.vio, cfg);
  return options;
}

void check_bridge_options(const InputGuardOptions& input, const estimator::VioOptions& vio, const Config& cfg) {
  if (input.bridge_max_gap_s > 0.0 && !vio.propagator.gap_noise.enabled()) {
    cfg.fail("input.bridge_max_gap_s", "bridging a gap needs estimator.imu_gap_noise (the unknown motion over it)");
  }
}

VinsNode::VinsNode(const VinsNodeOptions& options, StateCallback on_state, EventCallback on_event)
    : options_(options),
      estimator_(options.vio),
      on_state_(std::move(on_state)),
      on_event_(std::move(on_event)),
      imu_guard_("IMU", options.input.imu),
      frame_guard_("FEATURES", options.input.features),
      truth_guard_("GROUND_TRUTH", options.input.ground_truth) {
  options_.input.validate();
  if (options_.input.bridge_max_gap_s > 0.0 && !options_.vio.propagator.gap_noise.enabled()) {
    throw std::invalid_argument("input.bridge_max_gap_s needs estimator.imu_gap_noise");
  }
}

void VinsNode::set_frame_hooks(std::function<void(const CameraFrame&)> before_frame,
                               std::function<void()> after_update) {
  before_frame_ = std::move(before_frame);
  after_update_ = std::move(after_update);
}

void VinsNode::say(NodeEvent::Kind kind, const std::string& message) {
  if (on_event_) on_event_(NodeEvent{kind, message});
}

template <typename F>
void VinsNode::guarded(const char* where, F&& body) {
  try {
    body();
  } catch (const std::exception& e) {
    reset_estimate(std::string("internal error in ") + where + ": " + e.what(), /*clean_clock=*/false);
  }
}

void VinsNode::reset_estimate(const std::string& why, bool clean_clock) {
  ++resets_;
  estimator_.reset();
  gate_window_.clear();
  rejected_frames_ = 0;
  if (clean_clock) {
    estimator_.clear_imu();
    queued_frames_.clear();
    last_frame_utime_ = -1;
    for (StreamGuard* g : {&imu_guard_, &frame_guard_, &truth_guard_}) g->reset();
  }
  say(NodeEvent::Kind::kError, why + "; reset, re-initialising " +
                                   (options_.init_from_ground_truth ? "from ground truth" : "at rest"));
}

bool VinsNode::admit(StreamGuard& guard, int64_t utime) {
  const StreamCheck c = guard.check(utime);
  switch (c.verdict) {
    case StreamVerdict::kAccept:
      if (c.lost > 0 && on_event_) on_event_(NodeEvent{NodeEvent::Kind::kLost, c.message, c.lost, guard.name()});
      return true;
    case StreamVerdict::kRejectJump:
      say(NodeEvent::Kind::kDropped, c.message);
      return false;
    case StreamVerdict::kSourceReset:
      if (c.lost > 0 && on_event_) on_event_(NodeEvent{NodeEvent::Kind::kLost, c.message, c.lost, guard.name()});
      if (&guard == &truth_guard_) {
        say(NodeEvent::Kind::kInfo, c.message);  // not an input of the estimate: only its clock restarts
        return true;
      }
      // A short outage forward (the source restarted on its own schedule):
      // the guard's clock moved on, the estimate is propagated across it.
      std::string why = c.message;
      if (estimator_.initialized() && options_.input.bridge_max_gap_s > 0.0) {
        const int64_t last = &guard == &imu_guard_ ? estimator_.propagator().latest_utime() : last_frame_utime_;
        const double gap_s = 1e-6 * static_cast<double>(utime - last);
        if (last >= 0 && gap_s > 0.0 && gap_s <= options_.input.bridge_max_gap_s) {
          say(NodeEvent::Kind::kInfo, c.message + ": an outage of " + std::to_string(gap_s) +
                                          " s, the estimate is kept (bridged at the next frame)");
          return true;
        }
        why += " (longer than input.bridge_max_gap_s " + std::to_string(options_.input.bridge_max_gap_s) + " s)";
      }
      reset_estimate(why, /*clean_clock=*/true);
      guard.check(utime);  // the new clock starts here
      return true;
  }
  return false;
}

void VinsNode::count_left(EstimatorInput input, int64_t utime) {
  StreamGuard& guard = input == EstimatorInput::kImu     ? imu_guard_
                       : input == EstimatorInput::kFrame ? frame_guard_
                                                         : truth_guard_;
  const StreamCheck c = guard.check(utime);
  if (c.lost > 0 && on_event_) {
    on_event_(NodeEvent{NodeEvent::Kind::kLost, c.message + " (in the input left at the stop)", c.lost, guard.name()});
  }
}

const StreamGuard& VinsNode::guard(EstimatorInput input) const {
  return input == EstimatorInput::kImu ? imu_guard_ : input == EstimatorInput::kFrame ? frame_guard_ : truth_guard_;
}

bool VinsNode::enter(EstimatorInput input, int64_t utime) {
  if (!restore_tried_ && !options_.catch_up_log.empty() && !options_.checkpoint_path.empty()) {
    estimator::EstimatorCheckpoint c;
    if (restore_checkpoint(utime, "catching up from " + options_.catch_up_log, &c)) catch_up(c, input, utime);
  }
  if (utime > caught_until_[index(input)]) return true;
  ++already_handled_;
  return false;
}

void VinsNode::catch_up(const estimator::EstimatorCheckpoint& c, EstimatorInput live, int64_t live_utime) {
  // The state's frame and everything before it were handled by the process that wrote the checkpoint.
  for (int64_t& until : caught_until_) until = c.utime;
  last_frame_utime_ = c.utime;
  const std::string& path = options_.catch_up_log;
  std::unique_ptr<CatchUpLog> log;
  try {
    log = std::make_unique<CatchUpLog>(path, options_.catch_up_channels, c.utime);
  } catch (const std::exception& e) {
    say(NodeEvent::Kind::kInfo, std::string("no catch-up: ") + e.what() + "; bridging the gap");
    return;
  }
  // IMU samples read before the state's frame arrived before it at the
  // process too: they are in the estimator's buffer but their IMU-rate
  // outputs were published from the state before the frame.
  bool after_state_frame = false;
  bool reached_live = false;
  int64_t first = -1, last = -1;
  int64_t last_imu = c.last_imu.utime;
  double hole_s = 0.0;
  int64_t hole_end = -1;
  LoggedInput m;
  while (log->next(&m)) {
    if (m.input == live && m.utime >= live_utime) {
      reached_live = true;
      break;
    }
    if (m.input == EstimatorInput::kFrame && m.utime == c.utime) after_state_frame = true;
    if (m.utime <= caught_until_[index(m.input)]) continue;
    switch (m.input) {
      case EstimatorInput::kImu: {
        const double step_s = 1e-6 * static_cast<double>(m.utime - last_imu);
        if (step_s > hole_s) {
          hole_s = step_s;
          hole_end = m.utime;
        }
        last_imu = m.utime;
        on_imu_checked(m.imu, /*publish=*/after_state_frame);
        break;
      }
      case EstimatorInput::kFrame: on_frame_checked(m.frame); break;
      case EstimatorInput::kGroundTruth: on_ground_truth_checked(m.truth); break;
    }
    caught_until_[index(m.input)] = m.utime;
    ++caught_up_[index(m.input)];
    if (first < 0) first = m.utime;
    last = m.utime;
  }
  std::ostringstream msg;
  msg << "caught up " << caught_up_[index(EstimatorInput::kImu)] << " IMU, "
      << caught_up_[index(EstimatorInput::kFrame)] << " FEATURES, "
      << caught_up_[index(EstimatorInput::kGroundTruth)] << " GROUND_TRUTH from " << path;
  if (first >= 0) msg << " (" << first << " → " << last << ")";
  say(NodeEvent::Kind::kInfo, msg.str());
  for (const EstimatorInput input : {EstimatorInput::kImu, EstimatorInput::kFrame, EstimatorInput::kGroundTruth}) {
    if (caught_up_[index(input)] > 0 && on_event_) {
      on_event_(NodeEvent{NodeEvent::Kind::kCaughtUp, msg.str(), caught_up_[index(input)], guard(input).name()});
    }
  }
  if (log->malformed() > 0) {
    say(NodeEvent::Kind::kDropped, "catch-up log " + path + ": " + std::to_string(log->malformed()) +
                                       " malformed messages skipped (first: " + log->first_malformed() + ")");
  }
  if (hole_s > options_.input.max_imu_gap_s) {
    std::ostringstream hole;
    hole << "catch-up log " << path << " lacks " << hole_s << " s of IMU before utime " << hole_end
         << " (logger down?): bridging it";
    say(NodeEvent::Kind::kInfo, hole.str());
  }
  if (!reached_live) {
    std::ostringstream end;
    end << "catch-up log " << path << " ends " << 1e-6 * static_cast<double>(live_utime - std::max(last, c.utime))
        << " s before the live input at utime " << live_utime << ": bridging the rest";
    say(NodeEvent::Kind::kInfo, end.str());
  }
}

void VinsNode::on_imu(const ImuData& imu) {
  guarded("on_imu", [&] {
    if (enter(EstimatorInput::kImu, imu.utime)) on_imu_checked(imu, /*publish=*/true);
  });
}

void VinsNode::on_imu_checked(const ImuData& imu, bool publish) {
  // The clock first: a sample rejected for its values still took its slot
  // in the stream (counted once, as dropped, not again as lost).
  if (!admit(imu_guard_, imu.utime)) return;
  if (imu.w_IinI.allFinite() && imu.a_IinI.allFinite() &&
      (imu.w_IinI.norm() > options_.input.max_gyro_radps || imu.a_IinI.norm() > options_.input.max_accel_mps2)) {
    std::ostringstream msg;
    msg << "IMU sample at utime " << imu.utime << " out of range: |w| " << imu.w_IinI.norm() << " rad/s (limit "
        << options_.input.max_gyro_radps << "), |a| " << imu.a_IinI.norm() << " m/s^2 (limit "
        << options_.input.max_accel_mps2 << ")";
    say(NodeEvent::Kind::kDropped, msg.str());
    return;
  }
  const estimator::ImuFeedStatus status = estimator_.feed_imu(imu);
  switch (status) {
    case estimator::ImuFeedStatus::kAccepted:
      break;
    case estimator::ImuFeedStatus::kAcceptedAfterGap:
      say(NodeEvent::Kind::kInfo, "IMU gap before utime " + std::to_string(imu.utime) + " (propagating across it)");
      break;
    default:
      say(NodeEvent::Kind::kDropped,
          std::string("IMU sample at utime ") + std::to_string(imu.utime) + ": " + estimator::to_string(status));
      return;
  }
  try_restore(imu.utime);
  process_ready_frames(imu.utime);
  if (publish && options_.publish_imu_rate && queued_frames_.empty()) publish_propagated(imu.utime);
}

void VinsNode::on_frame(const CameraFrame& frame) {
  guarded("on_frame", [&] {
    if (enter(EstimatorInput::kFrame, frame.utime)) on_frame_checked(frame);
  });
}

void VinsNode::on_frame_checked(const CameraFrame& frame) {
  if (!admit(frame_guard_, frame.utime)) return;
  const std::string absurd = absurd_observation(frame);
  if (!absurd.empty()) {
    say(NodeEvent::Kind::kDropped, "camera frame at utime " + std::to_string(frame.utime) + ": " + absurd);
    return;
  }
  if (frame.utime <= last_frame_utime_) {
    say(NodeEvent::Kind::kDropped, "camera frame at utime " + std::to_string(frame.utime) +
                                       (frame.utime == last_frame_utime_ ? " is a duplicate" : " is out of order"));
    return;
  }
  last_frame_utime_ = frame.utime;
  queued_frames_.push_back(frame);
  process_ready_frames(estimator_.propagator().latest_utime());
  while (static_cast<int>(queued_frames_.size()) > options_.max_queued_frames) {
    say(NodeEvent::Kind::kInfo, "IMU stalled: processing frame " + std::to_string(queued_frames_.front().utime) +
                                    " without IMU up to its time");
    const CameraFrame stalled = std::move(queued_frames_.front());
    queued_frames_.pop_front();
    process_frame(stalled);
  }
}

void VinsNode::flush() {
  guarded("flush", [&] {
    while (!queued_frames_.empty()) {
      // Popped first: a frame that throws is not retried forever.
      const CameraFrame frame = std::move(queued_frames_.front());
      queued_frames_.pop_front();
      process_frame(frame);
    }
  });
}

bool VinsNode::check_ground_truth(GroundTruth* truth) {
  std::string why;
  const bool ok = truth->p_IinG.allFinite() && truth->v_IinG.allFinite() &&
                  validate_quaternion(&truth->q_GtoI, options_.input.max_quat_norm_error, &why) &&
                  (!truth->has_target ||
                   validate_quaternion(&truth->q_GtoT, options_.input.max_quat_norm_error, &why));
  if (!ok) {
    say(NodeEvent::Kind::kDropped, "ground truth at utime " + std::to_string(truth->utime) + ": " +
                                       (why.empty() ? std::string("non-finite position or velocity") : why));
  }
  return ok;
}

std::string VinsNode::absurd_observation(const CameraFrame& frame) const {
  const std::vector<CameraCalibration>& cams = options_.vio.cameras;
  const double max_n = options_.input.max_normalized;
  const double margin = options_.input.max_pixels_outside;
  for (const FeatureObservation& o : frame.observations) {
    std::ostringstream why;
    why << "feature " << o.feature_id << " ";
    if (o.camera_id < 0 || o.camera_id >= static_cast<int>(cams.size())) {
      why << "of camera " << o.camera_id << " (" << cams.size() << " calibrated)";
      return why.str();
    }
    if (!(std::abs(o.normalized.x()) <= max_n && std::abs(o.normalized.y()) <= max_n)) {
      why << "at normalized (" << o.normalized.x() << ", " << o.normalized.y() << "), beyond +-" << max_n;
      return why.str();
    }
    const CameraCalibration& c = cams[static_cast<std::size_t>(o.camera_id)];
    if (c.width > 0 && c.height > 0 &&
        !(o.pixel.x() >= -margin && o.pixel.x() <= c.width + margin && o.pixel.y() >= -margin &&
          o.pixel.y() <= c.height + margin)) {
      why << "at pixel (" << o.pixel.x() << ", " << o.pixel.y() << "), more than " << margin << " px outside the "
          << c.width << "x" << c.height << " image of camera " << o.camera_id;
      return why.str();
    }
  }
  return {};
}

bool VinsNode::on_ground_truth(const GroundTruth& message) {
  bool usable = false;
  guarded("on_ground_truth", [&] {
    usable = enter(EstimatorInput::kGroundTruth, message.utime) && on_ground_truth_checked(message);
  });
  return usable;
}

bool VinsNode::on_ground_truth_checked(const GroundTruth& message) {
  GroundTruth truth = message;
  const bool starting = options_.init_from_ground_truth && !estimator_.initialized();
  // A start far from the IMU's clock (a future or stale ground truth)
  // would make every frame "before the state time": wait for a good one.
  // Such a message never starts the stream's clock (it fills its slot in
  // a running one, so it is not counted again as lost).
  const int64_t imu_utime = estimator_.propagator().latest_utime();
  if (starting && imu_utime >= 0 &&
      std::abs(1e-6 * static_cast<double>(truth.utime - imu_utime)) > options_.input.max_imu_gap_s) {
    if (!truth_guard_.started() || admit(truth_guard_, truth.utime)) {
      say(NodeEvent::Kind::kDropped, "ground truth at utime " + std::to_string(truth.utime) +
                                         " is too far from the IMU clock (" + std::to_string(imu_utime) +
                                         ") to initialise from");
    }
    return false;
  }
  if (!admit(truth_guard_, truth.utime) || !check_ground_truth(&truth)) return false;
  if (starting) try_restore(truth.utime);
  if (starting && !estimator_.initialized()) initialise_from(truth);
  if (on_truth_) on_truth_(truth);
  return true;
}

void VinsNode::initialise_from(const GroundTruth& truth) {
  const estimator::InitialEstimate init = estimator::initial_estimate(truth, options_.vio, options_.perturb_seed);
  estimator_.initialize(init.value, truth.utime, init.P0);
  say(NodeEvent::Kind::kInfo, "initialised from ground truth at utime " + std::to_string(truth.utime));
}

void VinsNode::try_restore(int64_t input_utime) {
  if (restore_tried_ || options_.checkpoint_path.empty() || estimator_.initialized()) return;
  estimator::EstimatorCheckpoint c;
  restore_checkpoint(input_utime, "bridging the gap", &c);
}

bool VinsNode::restore_checkpoint(int64_t input_utime, const std::string& next, estimator::EstimatorCheckpoint* out) {
  restore_tried_ = true;
  estimator::EstimatorCheckpoint c;
  std::string why;
  const std::string start = std::string("; starting ") + (options_.init_from_ground_truth ? "from ground truth" : "at rest");
  if (!estimator::read_checkpoint(options_.checkpoint_path, &c, &why)) {
    // None yet is a normal first start; an unreadable one is a fault.
    const bool absent = why.rfind("no checkpoint", 0) == 0;
    say(absent ? NodeEvent::Kind::kInfo : NodeEvent::Kind::kError, why + start);
    return false;
  }
  const double age_s = 1e-6 * static_cast<double>(input_utime - c.utime);
  if (!(age_s >= 0.0 && age_s <= options_.input.bridge_max_gap_s)) {
    std::ostringstream msg;
    msg << "checkpoint " << options_.checkpoint_path << " rejected: stale, its utime " << c.utime << " is "
        << age_s << " s before the input (limit input.bridge_max_gap_s " << options_.input.bridge_max_gap_s
        << " s)" << start;
    say(NodeEvent::Kind::kInfo, msg.str());
    return false;
  }
  if (!estimator::restore(c, &estimator_, checkpoint_extension_, &why)) {
    say(NodeEvent::Kind::kError, "checkpoint " + options_.checkpoint_path + " rejected: " + why + start);
    return false;
  }
  restored_ = true;
  std::ostringstream msg;
  msg << "restored from checkpoint " << options_.checkpoint_path << " at utime " << c.utime << ", " << age_s
      << " s before the input: " << next;
  say(NodeEvent::Kind::kInfo, msg.str());
  *out = std::move(c);
  return true;
}

void VinsNode::write_checkpoint() {
  if (options_.checkpoint_path.empty()) return;
  std::string why;
  if (estimator::write_checkpoint(options_.checkpoint_path,
                                  estimator::checkpoint_of(estimator_, checkpoint_extension_), &why)) {
    return;
  }
  if (!std::exchange(checkpoint_failed_, true)) say(NodeEvent::Kind::kError, why + " (said once)");
}

bool VinsNode::bridges(double gap_s, const std::string& what) {
  if (!(gap_s <= options_.input.bridge_max_gap_s)) return false;
  ++bridged_gaps_;
  std::ostringstream msg;
  msg << what << ": bridged, the estimate kept and propagated across the " << gap_s
      << " s gap (input.bridge_max_gap_s " << options_.input.bridge_max_gap_s << " s)";
  say(NodeEvent::Kind::kInfo, msg.str());
  return true;
}

void VinsNode::process_ready_frames(int64_t latest_imu_utime) {
  while (!queued_frames_.empty() && queued_frames_.front().utime <= latest_imu_utime) {
    const CameraFrame frame = std::move(queued_frames_.front());
    queued_frames_.pop_front();
    process_frame(frame);
  }
}

void VinsNode::process_frame(const CameraFrame& frame) {
  if (estimator_.initialized()) {
    // IMU lost while frames continue: propagating blind would drift without
    // bound while every output looks fine.
    const double ahead_s = 1e-6 * static_cast<double>(frame.utime - estimator_.propagator().latest_utime());
    if (ahead_s > options_.input.max_imu_gap_s) {
      reset_estimate("no IMU for " + std::to_string(ahead_s) + " s at frame utime " + std::to_string(frame.utime) +
                         " (limit " + std::to_string(options_.input.max_imu_gap_s) + " s)",
                     /*clean_clock=*/false);
      return;
    }
  }
  if (before_frame_) before_frame_(frame);
  const estimator::FrameStatus status = estimator_.feed_camera(frame);
  rejected_frames_ = status == estimator::FrameStatus::kRejectedOutOfOrder ? rejected_frames_ + 1 : 0;
  switch (status) {
    case estimator::FrameStatus::kProcessed: {
      const estimator::PropagationReport& prop = estimator_.last_propagation();
      if (prop.max_step_s > options_.input.max_imu_gap_s) {
        const std::string gap = "frame at utime " + std::to_string(frame.utime) + " propagated across an IMU gap of " +
                                std::to_string(prop.max_step_s) + " s";
        if (!bridges(prop.max_step_s, gap)) {
          reset_estimate(gap + " (limit " + std::to_string(options_.input.max_imu_gap_s) +
                             " s; longer than input.bridge_max_gap_s " +
                             std::to_string(options_.input.bridge_max_gap_s) + " s)",
                         /*clean_clock=*/false);
          return;
        }
      }
      publish_updated();
      write_checkpoint();
      if (after_update_) after_update_();
      check_consistency();
      return;
    }
    case estimator::FrameStatus::kDiverged:
      reset_estimate("estimator diverged at utime " + std::to_string(frame.utime) + " (" +
                         estimator_.last_divergence().reason + ")",
                     /*clean_clock=*/false);
      return;
    case estimator::FrameStatus::kRejectedOutOfOrder:
      if (rejected_frames_ >= options_.input.max_rejected_frames) {
        reset_estimate(std::to_string(rejected_frames_) + " consecutive frames before the estimator's state time " +
                           std::to_string(estimator_.state_utime()) + " (its clock is wrong)",
                       /*clean_clock=*/false);
        return;
      }
      say(NodeEvent::Kind::kDropped,
          "frame at utime " + std::to_string(frame.utime) + ": " + estimator::to_string(status));
      return;
    case estimator::FrameStatus::kNotInitialized:
      say(NodeEvent::Kind::kDropped, "frame at utime " + std::to_string(frame.utime) + " before initialisation");
      return;
    default:
      say(NodeEvent::Kind::kDropped,
          "frame at utime " + std::to_string(frame.utime) + ": " + estimator::to_string(status));
      return;
  }
}

void VinsNode::check_consistency() {
  const estimator::UpdateStats& s = estimator_.last_stats();
  GateCounts g;
  g.failed = s.msckf_rejected_chi2 + s.slam_rejected_chi2;
  g.tested = s.msckf_used + s.slam_updated + g.failed;
  gate_window_.push_back(g);
  if (static_cast<int>(gate_window_.size()) > options_.input.consistency_window) gate_window_.pop_front();
  GateCounts sum;
  for (const GateCounts& w : gate_window_) {
    sum.tested += w.tested;
    sum.failed += w.failed;
  }
  if (static_cast<int>(gate_window_.size()) < options_.input.consistency_window ||
      sum.tested < options_.input.consistency_min_tests ||
      sum.failed <= options_.input.max_chi2_failure_fraction * sum.tested) {
    return;
  }
  std::ostringstream msg;
  msg << "filter inconsistent at utime " << estimator_.state_utime() << ": " << sum.failed << " of " << sum.tested
      << " features failed the chi2 gate over the last " << gate_window_.size() << " frames (limit "
      << options_.input.max_chi2_failure_fraction << ", about 0.05 when consistent)";
  reset_estimate(msg.str(), /*clean_clock=*/false);
}

void VinsNode::publish_updated() {
  imu_rate_count_ = 0;  // the IMU-rate phase follows the update (a restored node keeps it)
  if (on_state_) on_state_(estimator::nav_state_of(estimator_, /*updated=*/true));
}

void VinsNode::publish_propagated(int64_t utime) {
  if (!on_state_ || !estimator_.initialized() || utime <= estimator_.state_utime()) return;
  if (imu_rate_count_++ % options_.imu_rate_every != 0) return;
  // Output only: predicts the IMU marginal from the last update without
  // touching the filter, so IMU-rate output never changes the estimate.
  const estimator::ImuValue x0 = estimator_.imu_value();
  estimator::ImuValue x1;
  estimator::Matrix15d Phi, Q;
  estimator::PropagationReport report;
  if (!estimator_.propagator().predict_interval(x0, x0, estimator_.state_utime(), utime, &x1, &Phi, &Q, &report)) {
    return;
  }
  NavState s = estimator::nav_state_of(estimator_, /*updated=*/false);
  s.utime = utime;
  s.q_GtoI = x1.q_GtoI;
  s.p_IinG = x1.p_IinG;
  s.v_IinG = x1.v_IinG;
  s.bias_gyro = x1.bg;
  s.bias_accel = x1.ba;
  s.covariance = Phi * s.covariance * Phi.transpose() + Q;
  on_state_(s);
}

}  // namespace vimot

#include "procs/eval/log_eval.h"

#include <lcm/lcm-cpp.hpp>
#include <map>
#include <stdexcept>

#include "common/eval/json.h"
#include "common/eval/writers.h"
#include "common/math/quat.h"

#include "common/process/lcm_conversions.h"

namespace vimot {
namespace eval {

namespace {

// Decodes a whole event as Msg; lcm-gen decoders may throw on a corrupt
// array length instead of returning < 0: both are a malformed message.
template <typename Msg>
bool decode(const lcm::LogEvent& ev, Msg* msg, std::string* why) {
  try {
    if (msg->decode(ev.data, 0, ev.datalen) != ev.datalen) {
      *why = "does not decode as " + std::string(Msg::getTypeName());
      return false;
    }
  } catch (const std::exception& e) {
    *why = "does not decode as " + std::string(Msg::getTypeName()) + " (" + e.what() + ")";
    return false;
  }
  return true;
}

}  // namespace

int first_target_cell_index(const std::string& summary_json) {
  const JsonValue doc = JsonValue::parse(read_text_file(summary_json));
  const JsonValue& cells = doc.at("cells");
  for (std::size_t i = 0; i < cells.size(); ++i) {
    if (cells.at(i).at("mode").string() == "vio") continue;
    if (cells.at(i).at("runs").number() != 1.0) {
      throw std::runtime_error("'" + summary_json + "': compare needs a one-run summary (vimot-target-eval --runs 1)");
    }
    return static_cast<int>(i);
  }
  throw std::runtime_error("'" + summary_json + "' has no target-filter cell");
}

LogEvalResult evaluate_log(const std::string& path, const LogEvalOptions& options) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot open LCM log '" + path + "'");

  LogEvalResult r;
  TruthMatcher matcher;
  const bool scale_on = !options.scale_channel.empty();
  std::vector<scale::ScaleResult> estimates;
  std::vector<scale::ObjectPoseInWorld> metric_poses;
  std::vector<TargetStateEstimate> object_states;
  std::map<int64_t, GroundTruth> target_truths;  // for the metric poses
  auto malformed = [&r](int64_t* counter, const lcm::LogEvent& ev, const std::string& why) {
    ++*counter;
    if (r.first_malformed.empty()) {
      r.first_malformed = "event " + std::to_string(ev.eventnum) + " on " + ev.channel + ": " + why;
    }
  };
  // Decodes *ev as Msg, converts it and hands it to `use`; a message that
  // does not decode or convert counts as malformed in *counter.
  auto consume = [&](auto msg, const lcm::LogEvent& ev, int64_t* counter, auto use) {
    std::string why;
    if (!decode(ev, &msg, &why)) {
      malformed(counter, ev, why);
      return;
    }
    try {
      use(from_lcm(msg));
    } catch (const std::invalid_argument& e) {
      malformed(counter, ev, e.what());
    }
  };
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++r.events;
    if (ev->channel == options.state_channel) {
      consume(nav_state_t{}, *ev, &r.malformed_states, [&](const NavState& x) { matcher.add_state(x); });
    } else if (!options.target_channel.empty() && ev->channel == options.target_channel) {
      consume(target_state_t{}, *ev, &r.malformed_targets, [&](const TargetStateEstimate& x) { matcher.add_target(x); });
    } else if (scale_on && ev->channel == options.scale_channel) {
      consume(scale_estimate_t{}, *ev, &r.malformed_scale, [&](const scale::ScaleResult& x) { estimates.push_back(x); });
    } else if (scale_on && ev->channel == options.metric_channel) {
      consume(metric_object_pose_t{}, *ev, &r.malformed_scale,
              [&](const scale::ObjectPoseInWorld& x) { metric_poses.push_back(x); });
    } else if (scale_on && !options.object_state_channel.empty() && ev->channel == options.object_state_channel) {
      consume(target_state_t{}, *ev, &r.malformed_scale,
              [&](const TargetStateEstimate& x) { object_states.push_back(x); });
    } else if (ev->channel == options.truth_channel) {
      consume(ground_truth_t{}, *ev, &r.malformed_truths, [&](const GroundTruth& truth) {
        if (scale_on && truth.has_target) target_truths.emplace(truth.utime, truth);
        matcher.add_truth(truth);
      });
    }
  }
  r.samples = matcher.match(&r.counts);
  TrajectoryErrors errors;
  for (const ErrorSample& s : r.samples) errors.add(s);
  r.summary = errors.summary();
  if (!options.target_channel.empty()) {
    r.target_samples = matcher.match_targets(&r.target_counts, options.target_own_frame);
    TrajectoryErrors in_imu, in_world;
    for (const ErrorSample& s : r.target_samples.target_in_imu) in_imu.add(s);
    for (const ErrorSample& s : r.target_samples.target_in_world) in_world.add(s);
    r.target_in_imu = in_imu.summary();
    r.target_in_world = in_world.summary();
  }
  if (scale_on) {
    ScaleFigureBuilder figures;
    for (const TrackTruth& t : options.tracks) figures.start_track(t.start_utime, t.truth);
    for (const scale::ScaleResult& e : estimates) figures.add_estimate(e.utime, e.scale, e.accepted);
    std::map<int64_t, double> held_scales;  // of the metric pose of each frame
    for (const scale::ObjectPoseInWorld& p : metric_poses) {
      held_scales[p.utime] = p.scale;
      const auto it = target_truths.find(p.utime);
      if (it == target_truths.end()) {
        ++r.metric_without_truth;
        continue;
      }
      figures.add_metric_pose(p.utime, p.scale, p.R_OtoG, p.p_OinG, quat_to_rot(it->second.q_GtoT).transpose(),
                              it->second.p_TinG);
    }
    for (const TargetStateEstimate& s : object_states) {
      const auto it = target_truths.find(s.utime);
      const auto scale = held_scales.find(s.utime);
      if (it == target_truths.end() || scale == held_scales.end()) {
        ++r.object_states_without_truth;
        continue;
      }
      figures.add_filtered_pose(s, scale->second, quat_to_rot(it->second.q_GtoT).transpose(), it->second.p_TinG);
    }
    r.scale = figures.figures();
  }
  return r;
}

}  // namespace eval
}  // namespace vimot

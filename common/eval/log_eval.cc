#include "common/eval/log_eval.h"

#include <map>
#include <set>
#include <stdexcept>

#include "common/eval/json.h"
#include "common/eval/writers.h"
#include "common/math/quat.h"
#include "common/process/log_reader.h"
#include "common/time/utime.h"

namespace vimot {
namespace eval {

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
  LogReader log(path);
  LogEvalResult r;
  TruthMatcher matcher;
  const bool scale_on = !options.scale_channel.empty();
  std::vector<scale::ScaleResult> estimates;
  std::vector<scale::ObjectPoseInWorld> metric_poses;
  std::vector<TargetStateEstimate> object_states;
  std::map<int64_t, GroundTruth> target_truths;  // for the metric poses
  // A channel keeps its first handler: the state channel wins over the
  // others, the truth channel is the last resort (as the channels are meant).
  std::vector<int64_t> state_utimes;  // updated states, for the target kept
  std::set<int64_t> target_utimes;
  log.on_nav_state(
      options.state_channel,
      [&](const NavState& x) {
        if (x.utime < options.from_utime) return;
        matcher.add_state(x);
        if (x.updated) state_utimes.push_back(x.utime);
      },
      &r.malformed_states);
  log.on_target_state(
      options.target_channel,
      [&](const TargetStateEstimate& x) {
        if (x.utime < options.from_utime) return;
        matcher.add_target(x);
        target_utimes.insert(x.utime);
      },
      &r.malformed_targets);
  std::vector<CameraTargetBox> boxes, box_truths;
  if (!options.box_channel.empty()) {
    log.on_target_box(options.box_channel, [&](const CameraTargetBox& b) { boxes.push_back(b); }, &r.malformed_boxes);
    log.on_target_box(options.box_truth_channel, [&](const CameraTargetBox& b) { box_truths.push_back(b); },
                      &r.malformed_boxes);
  }
  if (scale_on) {
    log.on_scale_estimate(options.scale_channel, [&](const scale::ScaleResult& x) { estimates.push_back(x); },
                          &r.malformed_scale);
    log.on_metric_pose(options.metric_channel, [&](const scale::ObjectPoseInWorld& x) { metric_poses.push_back(x); },
                       &r.malformed_scale);
    log.on_target_state(options.object_state_channel,
                        [&](const TargetStateEstimate& x) { object_states.push_back(x); }, &r.malformed_scale);
  }
  log.on_ground_truth(
      options.truth_channel,
      [&](const GroundTruth& truth) {
        if (scale_on && truth.has_target) target_truths.emplace(truth.utime, truth);
        matcher.add_truth(truth);
      },
      &r.malformed_truths);
  r.events = log.read_all();
  r.first_malformed = log.first_malformed();
  r.samples = matcher.match(&r.counts);
  TrajectoryErrors errors;
  for (const ErrorSample& s : r.samples) errors.add(s);
  r.summary = errors.summary();
  if (!options.target_channel.empty()) {
    r.target_samples = matcher.match_targets(&r.target_counts, options.target_own_frame,
                                            seconds_to_utime(options.target_restart_gap_s));
    TrajectoryErrors in_imu, in_world;
    for (const ErrorSample& s : r.target_samples.target_in_imu) in_imu.add(s);
    for (const ErrorSample& s : r.target_samples.target_in_world) in_world.add(s);
    r.target_in_imu = in_imu.summary();
    r.target_in_world = in_world.summary();
    if (!target_utimes.empty()) {
      for (const int64_t t : state_utimes) {
        if (t < *target_utimes.begin()) continue;
        ++r.frames_since_target_start;
        r.frames_with_target += target_utimes.count(t) > 0 ? 1 : 0;
      }
    }
  }
  if (!options.box_channel.empty()) r.boxes = evaluate_boxes(boxes, box_truths);
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

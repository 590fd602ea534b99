#pragma once
// vimot-log-eval's core: reads an LCM log (lcm-logger, vimot-sim --log)
// through common/process/log_reader.h (its only LCM), and evaluates the
// estimator's updated states against the simulator's ground truth at the
// same utime with vimot_eval's metrics (TruthMatcher), so a recorded LCM run
// and an offline run are measured identically. A message that does not
// decode, or carries non-finite numbers, is counted and skipped, never fatal.

#include <cstdint>
#include <string>
#include <vector>

#include "common/eval/box_eval.h"
#include "common/eval/metrics.h"
#include "common/eval/scale_eval.h"
#include "common/eval/truth_matcher.h"

namespace vimot {
namespace eval {

struct LogEvalOptions {
  std::string state_channel{"VINS_STATE"};
  std::string truth_channel{"GROUND_TRUTH"};
  std::string target_channel;  // target_state_t; empty: no target evaluation
  /// The target filter started from its features (its own target frame):
  /// compare through the fixed transform at its first state (TruthMatcher).
  bool target_own_frame{false};
  /// With target_own_frame: target states further apart than this (s) are a
  /// restart of the target in a new frame (TruthMatcher::match_targets);
  /// 0: the frame is taken once.
  double target_restart_gap_s{0.0};
  /// Only states and target states at or after this utime are evaluated
  /// (e.g. what a restarted process published); 0: all.
  int64_t from_utime{0};
  // Monocular scale pipeline: scale_estimate_t and metric_object_pose_t
  // against the truth of the tracker's tracks (from vimot-scale-eval's
  // summary.json of the same seed: the object frame O is defined by the
  // tracker's initialisation, which the log does not carry).
  std::string scale_channel;   // empty: no scale evaluation
  std::string metric_channel;
  std::string object_state_channel;  // target_state_t of the object motion filter; empty: none
  std::vector<TrackTruth> tracks;
  // Segmented pipeline: target_box_t of the mask filter against the
  // rendered simulator's true boxes (box_eval.h); empty: none.
  std::string box_channel;
  std::string box_truth_channel{"TARGET_BOX_TRUTH"};
};

struct LogEvalResult {
  ErrorSummary summary;
  std::vector<ErrorSample> samples;  // utime order
  MatchCounts counts;
  int64_t events{0};                 // every event in the log
  int64_t malformed_states{0};       // on state_channel, not a valid nav_state_t
  int64_t malformed_truths{0};       // on truth_channel, not a valid ground_truth_t
  std::string first_malformed;       // what was wrong with the first one
  // Target (target_channel given): errors in both frames, see TargetMatch.
  ErrorSummary target_in_imu;
  ErrorSummary target_in_world;
  TargetMatch target_samples;
  TargetMatchCounts target_counts;
  int64_t malformed_targets{0};
  /// Target kept (target_channel given): updated states on state_channel
  /// from the first target state on, and those with a target state at
  /// their utime.
  int64_t frames_since_target_start{0};
  int64_t frames_with_target{0};
  std::vector<BoxCameraFigures> boxes;  // box_channel given: per camera
  int64_t malformed_boxes{0};
  ScaleFigures scale;
  int64_t malformed_scale{0};   // on scale_channel, metric_channel or object_state_channel
  int64_t metric_without_truth{0};
  int64_t object_states_without_truth{0};
};

/// Index in "cells" of the first target-filter cell (not VIO-only) of a
/// vimot-target-eval summary.json made with --runs 1. Throws
/// std::runtime_error if there is none or it has more than one run.
int first_target_cell_index(const std::string& summary_json);

/// Throws std::runtime_error if the log cannot be opened.
LogEvalResult evaluate_log(const std::string& path, const LogEvalOptions& options = {});

}  // namespace eval
}  // namespace vimot

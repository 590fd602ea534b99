#pragma once
// Pairs published estimates with ground truth by exact utime, for
// evaluating a recorded run (vimot-log-eval). Only states with
// updated = true (right after a camera update) are evaluated, the same
// samples run_vio_on_sim uses. Arrival order does not matter: states and
// truths are collected, then matched. No LCM here.

#include <cstdint>
#include <map>
#include <vector>

#include "common/eval/metrics.h"
#include "common/eval/target_frame.h"
#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"
#include "common/types/target_state.h"

namespace vimot {
namespace eval {

struct MatchCounts {
  int64_t states{0};            // every state given
  int64_t updated_states{0};    // with updated = true
  int64_t duplicate_states{0};  // updated state at a utime already seen (first kept)
  int64_t truths{0};
  int64_t duplicate_truths{0};  // (first kept)
  int64_t matched{0};           // updated states with truth at the same utime
  int64_t unmatched{0};         // updated states without
  int64_t bad_covariance{0};    // matched, but a 3×3 block not positive definite (skipped)
};

struct TargetMatchCounts {
  int64_t states{0};
  int64_t duplicate_states{0};  // at a utime already seen (first kept)
  int64_t matched{0};           // with truth carrying the target at the same utime
  int64_t unmatched{0};
  int64_t bad_covariance{0};    // matched, but a 3×3 block not positive definite (skipped)
};

/// Target errors in both frames, as vimot-target-eval's (run_target_on_sim).
/// A published target state carries the covariance of the filter's
/// representation only, so NEES and 3σ are filled in that frame and NaN in
/// the other (its covariance needs the robot's, which is not published).
struct TargetMatch {
  std::vector<ErrorSample> target_in_imu;    // [q_ItoT, p_TinI]
  std::vector<ErrorSample> target_in_world;  // [q_GtoT, p_TinG]
  /// The filter's target frame in the true one (identity unless own_frame;
  /// the last one taken).
  TargetFrameTransform target_frame;
  /// Times the frame was taken again (start_count changed, or a restart gap).
  int64_t frame_restarts{0};
};

class TruthMatcher {
 public:
  void add_state(const NavState& state);
  void add_target(const TargetStateEstimate& target);
  void add_truth(const GroundTruth& truth);

  /// Matches everything given so far; samples in utime order.
  std::vector<ErrorSample> match(MatchCounts* counts) const;
  /// own_frame: the filter defined its own target frame (init mode
  /// features); the truth is taken in it, through the fixed transform at the
  /// first matched target state (target_frame.h). The frame is taken again at
  /// the first matched state after a new start: the state's start_count
  /// changed (the filter started the target again), or, restart_gap_us > 0,
  /// target states more than this apart (a respawned process, a reset).
  TargetMatch match_targets(TargetMatchCounts* counts, bool own_frame = false, int64_t restart_gap_us = 0) const;

 private:
  std::map<int64_t, NavState> states_;  // updated states by utime
  std::map<int64_t, TargetStateEstimate> targets_;
  std::map<int64_t, GroundTruth> truths_;
  MatchCounts counts_;
  TargetMatchCounts target_counts_;
};

}  // namespace eval
}  // namespace vimot

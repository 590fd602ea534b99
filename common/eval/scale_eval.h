#pragma once
// Evaluation of the monocular metric-scale pipeline of the scale paper
// (Qiu et al., Sec. III-IV) against the simulator's truth, for an offline
// run (procs/eval/scale_run.h, vimot-scale-eval) and for a recorded LCM run
// (common/eval/log_eval.h, vimot-log-eval) alike. No LCM here.
//
// Truth per tracker track (common/eval/object_truth.h): s_true and the object
// frame O rigid in the target T. Reported as the paper reports its trials:
//  * scale: relative error ŝ/s_true − 1 of every accepted estimate (median,
//    max |·|) and of the scale held at the end;
//  * object in world (each published metric pose, Eq. 21): error p̂_OinG −
//    p_OinG per axis of G, mean and standard deviation (m); orientation
//    error R̂_OtoG R_OtoGᵀ as yaw (about z of G), pitch, roll (ZYX), mean and
//    standard deviation (rad);
//  * the object motion filter's states (OBJECT_STATE, docs/object_motion_filter.md)
//    the same way, plus their NEES: position (3 dof, δp in G) and
//    orientation (3 dof, δθ in O, R_GtoO = Exp(−δθ) R̂_GtoO), each averaged.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/eval/json.h"
#include "common/eval/metrics.h"
#include "common/eval/object_truth.h"
#include "common/types/target_state.h"

namespace vimot {
namespace eval {

/// One published metric object pose against the truth.
struct MetricPoseSample {
  int64_t utime{0};
  double scale{0.0};       // the held scale used
  double scale_true{0.0};  // s_true of the track
  Eigen::Vector3d err_p{Eigen::Vector3d::Zero()};    // m, p̂_OinG − p_OinG (G)
  Eigen::Vector3d err_ypr{Eigen::Vector3d::Zero()};  // rad, yaw, pitch, roll of R̂_OtoG R_OtoGᵀ
};

/// The error of one metric object pose (R̂_OtoG, p̂_OinG) against the truth:
/// the track's object frame in T and the true target pose (R_TtoG, p_TinG).
MetricPoseSample metric_pose_error(int64_t utime, double scale, const Eigen::Matrix3d& R_OtoG,
                                   const Eigen::Vector3d& p_OinG, const ObjectTruth& truth,
                                   const Eigen::Matrix3d& R_TtoG, const Eigen::Vector3d& p_TinG);

/// One filtered object state (T = O) against the truth: the pose error as
/// metric_pose_error's (scale: the held scale of the same frame) and its NEES.
struct FilteredPoseSample {
  MetricPoseSample error;
  double nees_p{0.0};      // 3 dof
  double nees_theta{0.0};  // 3 dof
};

struct MeanStd3 {
  Eigen::Vector3d mean{Eigen::Vector3d::Zero()};
  Eigen::Vector3d std{Eigen::Vector3d::Zero()};  // sample standard deviation (n − 1)
};
MeanStd3 mean_std3(const std::vector<Eigen::Vector3d>& values);

/// The figures of a run (offline or from an LCM log, see vimot-log-eval).
struct ScaleFigures {
  int64_t estimates{0};                       // SCALE_ESTIMATE
  int64_t accepted{0};
  std::vector<double> accepted_scale_errors;  // ŝ/s_true − 1 of the accepted estimates
  double final_scale_error{0.0};              // of the last accepted estimate (NaN if none)
  std::vector<MetricPoseSample> metric_poses;
  MeanStd3 position_error;     // m, over metric_poses
  MeanStd3 orientation_error;  // rad, yaw / pitch / roll
  // The object motion filter's states (OBJECT_STATE).
  std::vector<FilteredPoseSample> filtered_poses;
  MeanStd3 filtered_position_error;     // m
  MeanStd3 filtered_orientation_error;  // rad, yaw / pitch / roll
  double filtered_nees_position{0.0};     // mean over filtered_poses (0 if none)
  double filtered_nees_orientation{0.0};
};

/// Accumulates estimates and metric poses into ScaleFigures; the truth of
/// each tracker track is given as the track starts.
class ScaleFigureBuilder {
 public:
  /// Metric poses and estimates from `utime` on belong to this track.
  void start_track(int64_t utime, const ObjectTruth& truth);
  void add_estimate(int64_t utime, double scale, bool accepted);
  void add_metric_pose(int64_t utime, double scale, const Eigen::Matrix3d& R_OtoG, const Eigen::Vector3d& p_OinG,
                       const Eigen::Matrix3d& R_TtoG, const Eigen::Vector3d& p_TinG);
  /// A filtered object state (global representation, T = O) with the scale
  /// held for its frame.
  void add_filtered_pose(const TargetStateEstimate& state, double scale, const Eigen::Matrix3d& R_TtoG,
                         const Eigen::Vector3d& p_TinG);
  ScaleFigures figures() const;

 private:
  const ObjectTruth* truth_at(int64_t utime) const;
  std::vector<std::pair<int64_t, ObjectTruth>> tracks_;  // (start utime, truth), increasing
  ScaleFigures f_;
};

/// A track's truth and where it starts, as written to vimot-scale-eval's
/// summary.json (so an LCM run of the same seed can be evaluated with it).
struct TrackTruth {
  int64_t track_id{0};
  int64_t start_utime{0};  // first valid object pose of the track
  ObjectTruth truth;
};

struct ScaleRunResult {
  uint64_t sim_seed{0};
  uint64_t perturb_seed{0};
  int64_t frames{0};
  int64_t tracker_valid_frames{0};
  std::vector<TrackTruth> tracks;
  ScaleFigures figures;
  ErrorSummary vio;            // camera-rate VIO accuracy (as vimot-vio-eval)
  double tracker_ms_mean{0.0};
  double filter_us_mean{0.0};  // µs, object motion filter per accepted metric pose (update, outputs, prediction)
  bool vio_diverged{false};
  std::string divergence_reason;
  double wall_s{0.0};
};

/// The median of |errors| and the largest |error|; zeros when empty.
struct AbsStats {
  double median{0.0};
  double max{0.0};
};
AbsStats abs_stats(const std::vector<double>& errors);

/// One run as an object of vimot-scale-eval's summary.json ("per_run"):
/// its figures and its tracks' truth.
void write_scale_run_json(JsonWriter& json, const ScaleRunResult& run);
/// Run `run` of a summary.json: its tracks' truth, and its figures (without
/// the per-pose samples). Throw std::runtime_error naming the file.
std::vector<TrackTruth> read_track_truths(const std::string& summary_json, std::size_t run);
ScaleFigures read_scale_figures(const std::string& summary_json, std::size_t run);

}  // namespace eval
}  // namespace vimot

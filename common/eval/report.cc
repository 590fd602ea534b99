#include "common/eval/report.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "common/eval/json.h"
#include "common/eval/writers.h"

namespace vimot {
namespace eval {

RunAverages average_runs(const std::vector<SimRunResult>& runs) {
  RunAverages a;
  a.errors = aggregate(runs);
  if (runs.empty()) return a;
  const double n = static_cast<double>(runs.size());
  for (const SimRunResult& r : runs) {
    a.path_length_m += r.path_length_m / n;
    a.ate4_position_m += r.aligned.ate_position_m / n;
    a.ate4_orientation_deg += r.aligned.ate_orientation_deg / n;
    a.timing.mean_ms += r.timing.mean_ms / n;
    a.timing.median_ms += r.timing.median_ms / n;
    a.timing.p95_ms += r.timing.p95_ms / n;
    a.timing.max_ms = std::max(a.timing.max_ms, r.timing.max_ms);
    a.timing.count += r.timing.count;
    a.frames += static_cast<double>(r.errors.count) / n;
    a.msckf_used += r.totals.msckf_used / n;
    a.slam_initialized += r.totals.slam_initialized / n;
    a.slam_updated += r.totals.slam_updated / n;
    a.diverged += r.diverged ? 1 : 0;
  }
  return a;
}

namespace {

std::string row(const std::string& label, const ErrorSummary& e, double path, const TimingStats& t, double frames,
                double msckf, double slam_init, double slam_upd, double ate_p, double ate_o, const std::string& flag) {
  char buf[360];
  std::snprintf(buf, sizeof(buf),
                "%-6s %9.4f %9.4f %7.2f %7.2f %8.1f %7.2f %7.2f %7.2f %7.0f %8.0f %7.0f %8.0f %8.4f %8.4f  %s",
                label.c_str(), e.rmse_position_m, e.rmse_orientation_deg, e.nees_position, e.nees_orientation, path,
                t.mean_ms, t.p95_ms, t.max_ms, frames, msckf, slam_init, slam_upd, ate_p, ate_o, flag.c_str());
  return buf;
}

}  // namespace

std::string results_table(const std::vector<SimRunResult>& runs) {
  std::ostringstream s;
  s << "seed    pos RMSE  ori RMSE  NEES p  NEES o   path m  ms avg  ms p95  ms max  frames    MSCKF SLAMini  SLAMupd"
       "   ATE4 p   ATE4 o\n"
    << "             [m]     [deg]                          per-frame CPU time                                   "
       "      [m]    [deg]\n";
  for (const SimRunResult& r : runs) {
    s << row(std::to_string(r.sim_seed), r.errors, r.path_length_m, r.timing, static_cast<double>(r.errors.count),
             r.totals.msckf_used, r.totals.slam_initialized, r.totals.slam_updated, r.aligned.ate_position_m,
             r.aligned.ate_orientation_deg, r.diverged ? "DIVERGED: " + r.divergence_reason : "")
      << "\n";
  }
  const RunAverages a = average_runs(runs);
  ErrorSummary mean;
  mean.rmse_position_m = a.errors.rmse_position_m.mean;
  mean.rmse_orientation_deg = a.errors.rmse_orientation_deg.mean;
  mean.nees_position = a.errors.nees_position.mean;
  mean.nees_orientation = a.errors.nees_orientation.mean;
  s << row("mean", mean, a.path_length_m, a.timing, a.frames, a.msckf_used, a.slam_initialized, a.slam_updated,
           a.ate4_position_m, a.ate4_orientation_deg, a.diverged > 0 ? std::to_string(a.diverged) + " diverged" : "")
    << "\n";
  char buf[200];
  if (runs.size() > 1) {
    std::snprintf(buf, sizeof(buf), "%-6s %9.4f %9.4f %7.2f %7.2f", "std", a.errors.rmse_position_m.std,
                  a.errors.rmse_orientation_deg.std, a.errors.nees_position.std, a.errors.nees_orientation.std);
    s << buf << "\n";
  }
  std::snprintf(buf, sizeof(buf), "%-6s %9.4f %9.4f   RMSE the filter's covariance predicts, sqrt(mean tr P)",
                "pred", a.errors.predicted_rmse_position_m.mean, a.errors.predicted_rmse_orientation_deg.mean);
  s << buf << "\n";
  return s.str();
}

namespace {
void write_timing(JsonWriter& j, const TimingStats& t) {
  j.begin_object();
  j.field("mean_ms", t.mean_ms).field("median_ms", t.median_ms).field("p95_ms", t.p95_ms).field("max_ms", t.max_ms);
  j.field("frames", t.count);
  j.end_object();
}
}  // namespace

std::string summary_json(const std::vector<SimRunResult>& runs, const RunContext& c) {
  const RunAverages a = average_runs(runs);
  JsonWriter j;
  j.begin_object();
  j.field("tool", "vimot-vio-eval");
  j.field("sim_config", c.sim_config);
  j.field("vins_config", c.vins_config);
  j.field("runs", static_cast<int64_t>(runs.size()));
  j.field("first_seed", c.first_seed);
  j.field("perturb", c.perturb);
  j.field("threads", c.threads);
  j.field("wall_s", c.wall_s);
  j.key("machine").begin_object().field("nproc", c.machine.nproc).field("cpu_model", c.machine.cpu_model).end_object();
  ErrorSummary mean;
  mean.rmse_position_m = a.errors.rmse_position_m.mean;
  mean.rmse_orientation_deg = a.errors.rmse_orientation_deg.mean;
  mean.nees_position = a.errors.nees_position.mean;
  mean.nees_orientation = a.errors.nees_orientation.mean;
  mean.predicted_rmse_position_m = a.errors.predicted_rmse_position_m.mean;
  mean.predicted_rmse_orientation_deg = a.errors.predicted_rmse_orientation_deg.mean;
  mean.count = a.errors.samples;
  j.key("summary");
  write_summary_json(j, mean);
  j.key("std").begin_object();
  j.field("rmse_position_m", a.errors.rmse_position_m.std);
  j.field("rmse_orientation_deg", a.errors.rmse_orientation_deg.std);
  j.field("nees_position", a.errors.nees_position.std);
  j.field("nees_orientation", a.errors.nees_orientation.std);
  j.end_object();
  j.field("path_length_m", a.path_length_m);
  j.key("aligned_4dof").begin_object();
  j.field("ate_position_m", a.ate4_position_m).field("ate_orientation_deg", a.ate4_orientation_deg).end_object();
  j.key("timing");
  write_timing(j, a.timing);
  j.field("diverged_runs", a.diverged);
  j.key("per_run").begin_array();
  for (const SimRunResult& r : runs) {
    j.begin_object();
    j.field("sim_seed", r.sim_seed).field("perturb_seed", r.perturb_seed);
    j.key("summary");
    write_summary_json(j, r.errors);
    j.key("aligned_4dof").begin_object();
    j.field("ate_position_m", r.aligned.ate_position_m).field("ate_orientation_deg", r.aligned.ate_orientation_deg);
    j.field("yaw_rad", r.aligned.alignment.yaw).end_object();
    j.field("path_length_m", r.path_length_m).field("duration_s", r.duration_s);
    j.key("timing");
    write_timing(j, r.timing);
    j.field("camera_frames", r.camera_frames).field("frames_processed", r.frames_processed);
    j.field("frames_dropped", r.frames_dropped).field("frames_without_truth", r.frames_without_truth);
    j.key("updates").begin_object();
    j.field("msckf_used", r.totals.msckf_used).field("msckf_rejected_chi2", r.totals.msckf_rejected_chi2);
    j.field("msckf_rejected_triangulation", r.totals.msckf_rejected_triangulation);
    j.field("msckf_dropped_over_max", r.totals.msckf_dropped_over_max);
    j.field("slam_initialized", r.totals.slam_initialized).field("slam_updated", r.totals.slam_updated);
    j.field("slam_rejected_chi2", r.totals.slam_rejected_chi2).field("slam_marginalized", r.totals.slam_marginalized);
    j.end_object();
    j.field("diverged", r.diverged).field("divergence_reason", r.divergence_reason);
    j.field("wall_s", r.wall_s);
    j.end_object();
  }
  j.end_array();
  j.end_object();
  return j.str();
}

std::string summary_csv(const std::vector<SimRunResult>& runs) {
  std::ostringstream s;
  s << "seed,perturb_seed,rmse_position_m,rmse_orientation_deg,nees_position,nees_orientation,samples,"
       "path_length_m,frame_ms_mean,frame_ms_median,frame_ms_p95,frame_ms_max,msckf_used,slam_initialized,"
       "slam_updated,diverged,predicted_rmse_position_m,predicted_rmse_orientation_deg\n";
  char buf[512];
  for (const SimRunResult& r : runs) {
    std::snprintf(buf, sizeof(buf),
                  "%llu,%llu,%.9g,%.9g,%.9g,%.9g,%lld,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%d,%d,%d,%.9g,%.9g\n",
                  static_cast<unsigned long long>(r.sim_seed), static_cast<unsigned long long>(r.perturb_seed),
                  r.errors.rmse_position_m, r.errors.rmse_orientation_deg, r.errors.nees_position,
                  r.errors.nees_orientation, static_cast<long long>(r.errors.count), r.path_length_m, r.timing.mean_ms,
                  r.timing.median_ms, r.timing.p95_ms, r.timing.max_ms, r.totals.msckf_used,
                  r.totals.slam_initialized, r.totals.slam_updated, r.diverged ? 1 : 0,
                  r.errors.predicted_rmse_position_m, r.errors.predicted_rmse_orientation_deg);
    s << buf;
  }
  const RunAverages a = average_runs(runs);
  std::snprintf(buf, sizeof(buf),
                "mean,,%.9g,%.9g,%.9g,%.9g,%lld,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,%.9g,%.9g\n",
                a.errors.rmse_position_m.mean, a.errors.rmse_orientation_deg.mean, a.errors.nees_position.mean,
                a.errors.nees_orientation.mean, static_cast<long long>(a.errors.samples), a.path_length_m,
                a.timing.mean_ms, a.timing.median_ms, a.timing.p95_ms, a.timing.max_ms, a.msckf_used,
                a.slam_initialized, a.slam_updated, a.diverged, a.errors.predicted_rmse_position_m.mean,
                a.errors.predicted_rmse_orientation_deg.mean);
  s << buf;
  return s.str();
}

}  // namespace eval
}  // namespace vimot

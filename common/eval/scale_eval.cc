#include "common/eval/scale_eval.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/eval/writers.h"
#include "common/math/quat.h"

namespace vimot {
namespace eval {

namespace {

// Z-Y-X (yaw about z, then pitch about y, then roll about x) angles of R.
Eigen::Vector3d yaw_pitch_roll(const Eigen::Matrix3d& R) {
  return Eigen::Vector3d(std::atan2(R(1, 0), R(0, 0)), -std::asin(std::clamp(R(2, 0), -1.0, 1.0)),
                         std::atan2(R(2, 1), R(2, 2)));
}

void write_vec(JsonWriter& j, const std::string& key, const Eigen::Vector3d& v) {
  j.key(key).begin_array();
  for (int i = 0; i < 3; ++i) j.value(v(i));
  j.end_array();
}

Eigen::Vector3d read_vec(const JsonValue& a) {
  if (a.size() != 3) throw std::runtime_error("expected 3 numbers");
  return Eigen::Vector3d(a.at(std::size_t{0}).number(), a.at(std::size_t{1}).number(), a.at(std::size_t{2}).number());
}

const JsonValue& run_object(const JsonValue& doc, std::size_t run) {
  const JsonValue& runs = doc.at("per_run");
  if (run >= runs.size()) throw std::runtime_error("no run " + std::to_string(run) + " in per_run");
  return runs.at(run);
}

}  // namespace

MetricPoseSample metric_pose_error(int64_t utime, double scale, const Eigen::Matrix3d& R_OtoG,
                                   const Eigen::Vector3d& p_OinG, const ObjectTruth& truth,
                                   const Eigen::Matrix3d& R_TtoG, const Eigen::Vector3d& p_TinG) {
  MetricPoseSample m;
  m.utime = utime;
  m.scale = scale;
  m.scale_true = truth.s_true;
  m.err_p = p_OinG - (R_TtoG * truth.p_OinT + p_TinG);
  m.err_ypr = yaw_pitch_roll(R_OtoG * (R_TtoG * truth.R_OtoT).transpose());
  return m;
}

MeanStd3 mean_std3(const std::vector<Eigen::Vector3d>& values) {
  MeanStd3 r;
  if (values.empty()) return r;
  for (const auto& v : values) r.mean += v;
  r.mean /= static_cast<double>(values.size());
  if (values.size() < 2) return r;
  Eigen::Vector3d sq = Eigen::Vector3d::Zero();
  for (const auto& v : values) sq += (v - r.mean).cwiseAbs2();
  r.std = (sq / static_cast<double>(values.size() - 1)).cwiseSqrt();
  return r;
}

AbsStats abs_stats(const std::vector<double>& errors) {
  AbsStats s;
  if (errors.empty()) return s;
  std::vector<double> a;
  for (double e : errors) a.push_back(std::abs(e));
  std::sort(a.begin(), a.end());
  s.median = a.size() % 2 == 1 ? a[a.size() / 2] : 0.5 * (a[a.size() / 2 - 1] + a[a.size() / 2]);
  s.max = a.back();
  return s;
}

void ScaleFigureBuilder::start_track(int64_t utime, const ObjectTruth& truth) {
  if (!tracks_.empty() && utime <= tracks_.back().first) {
    throw std::invalid_argument("ScaleFigureBuilder: tracks must start in time order");
  }
  tracks_.emplace_back(utime, truth);
}

const ObjectTruth* ScaleFigureBuilder::truth_at(int64_t utime) const {
  const ObjectTruth* t = nullptr;
  for (const auto& [start, truth] : tracks_) {
    if (start <= utime) t = &truth;
  }
  return t;
}

void ScaleFigureBuilder::add_estimate(int64_t utime, double scale, bool accepted) {
  ++f_.estimates;
  const ObjectTruth* truth = truth_at(utime);
  if (!accepted || truth == nullptr) return;
  ++f_.accepted;
  f_.accepted_scale_errors.push_back(scale / truth->s_true - 1.0);
}

void ScaleFigureBuilder::add_filtered_pose(const TargetStateEstimate& state, double scale,
                                           const Eigen::Matrix3d& R_TtoG, const Eigen::Vector3d& p_TinG) {
  const ObjectTruth* truth = truth_at(state.utime);
  if (truth == nullptr) return;
  FilteredPoseSample f;
  const Eigen::Matrix3d R_OtoG = quat_to_rot(state.q_GtoT).transpose();
  f.error = metric_pose_error(state.utime, scale, R_OtoG, state.p_TinG, *truth, R_TtoG, p_TinG);
  const Eigen::Matrix3d R_OtoG_true = R_TtoG * truth->R_OtoT;
  const ErrorSample e = compute_error(state.utime, rot_to_quat(R_OtoG_true.transpose()),
                                      R_TtoG * truth->p_OinT + p_TinG, state.q_GtoT, state.p_TinG,
                                      state.covariance.topLeftCorner<3, 3>(), state.covariance.block<3, 3>(3, 3));
  f.nees_p = e.nees_p;
  f.nees_theta = e.nees_theta;
  f_.filtered_poses.push_back(f);
}

void ScaleFigureBuilder::add_metric_pose(int64_t utime, double scale, const Eigen::Matrix3d& R_OtoG,
                                         const Eigen::Vector3d& p_OinG, const Eigen::Matrix3d& R_TtoG,
                                         const Eigen::Vector3d& p_TinG) {
  if (const ObjectTruth* truth = truth_at(utime)) {
    f_.metric_poses.push_back(metric_pose_error(utime, scale, R_OtoG, p_OinG, *truth, R_TtoG, p_TinG));
  }
}

ScaleFigures ScaleFigureBuilder::figures() const {
  ScaleFigures f = f_;
  f.final_scale_error = f.accepted_scale_errors.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                        : f.accepted_scale_errors.back();
  std::vector<Eigen::Vector3d> p, o;
  for (const MetricPoseSample& m : f.metric_poses) {
    p.push_back(m.err_p);
    o.push_back(m.err_ypr);
  }
  f.position_error = mean_std3(p);
  f.orientation_error = mean_std3(o);
  p.clear();
  o.clear();
  double nees_p = 0.0, nees_theta = 0.0;
  for (const FilteredPoseSample& s : f.filtered_poses) {
    p.push_back(s.error.err_p);
    o.push_back(s.error.err_ypr);
    nees_p += s.nees_p;
    nees_theta += s.nees_theta;
  }
  f.filtered_position_error = mean_std3(p);
  f.filtered_orientation_error = mean_std3(o);
  if (!f.filtered_poses.empty()) {
    f.filtered_nees_position = nees_p / static_cast<double>(f.filtered_poses.size());
    f.filtered_nees_orientation = nees_theta / static_cast<double>(f.filtered_poses.size());
  }
  return f;
}

void write_scale_run_json(JsonWriter& j, const ScaleRunResult& r) {
  const ScaleFigures& f = r.figures;
  const AbsStats s = abs_stats(f.accepted_scale_errors);
  j.begin_object();
  j.field("sim_seed", r.sim_seed).field("perturb_seed", r.perturb_seed).field("frames", r.frames);
  j.field("tracker_valid_frames", r.tracker_valid_frames);
  j.field("estimates", f.estimates).field("accepted", f.accepted);
  j.field("scale_error_median", s.median).field("scale_error_max", s.max);
  j.field("final_scale_error", f.final_scale_error);
  j.field("metric_poses", static_cast<int64_t>(f.metric_poses.size()));
  write_vec(j, "position_error_mean_m", f.position_error.mean);
  write_vec(j, "position_error_std_m", f.position_error.std);
  write_vec(j, "ypr_error_mean_rad", f.orientation_error.mean);
  write_vec(j, "ypr_error_std_rad", f.orientation_error.std);
  j.field("filtered_poses", static_cast<int64_t>(f.filtered_poses.size()));
  write_vec(j, "filtered_position_error_mean_m", f.filtered_position_error.mean);
  write_vec(j, "filtered_position_error_std_m", f.filtered_position_error.std);
  write_vec(j, "filtered_ypr_error_mean_rad", f.filtered_orientation_error.mean);
  write_vec(j, "filtered_ypr_error_std_rad", f.filtered_orientation_error.std);
  j.field("filtered_nees_position", f.filtered_nees_position);
  j.field("filtered_nees_orientation", f.filtered_nees_orientation);
  j.key("vio");
  write_summary_json(j, r.vio);
  j.field("tracker_ms_mean", r.tracker_ms_mean).field("filter_us_mean", r.filter_us_mean);
  j.field("vio_diverged", r.vio_diverged).field("wall_s", r.wall_s);
  j.key("tracks").begin_array();
  for (const TrackTruth& t : r.tracks) {
    j.begin_object();
    j.field("track_id", t.track_id).field("start_utime", t.start_utime).field("s_true", t.truth.s_true);
    write_vec(j, "p_OinT", t.truth.p_OinT);
    j.key("q_OtoT").begin_array();
    const Eigen::Vector4d q = rot_to_quat(t.truth.R_OtoT);
    for (int i = 0; i < 4; ++i) j.value(q(i));
    j.end_array();
    j.end_object();
  }
  j.end_array();
  j.end_object();
}

std::vector<TrackTruth> read_track_truths(const std::string& summary_json, std::size_t run) {
  try {
    const JsonValue doc = JsonValue::parse(read_text_file(summary_json));
    const JsonValue& tracks = run_object(doc, run).at("tracks");
    std::vector<TrackTruth> out;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
      const JsonValue& t = tracks.at(i);
      TrackTruth tt;
      tt.track_id = static_cast<int64_t>(t.at("track_id").number());
      tt.start_utime = static_cast<int64_t>(t.at("start_utime").number());
      tt.truth.s_true = t.at("s_true").number();
      tt.truth.p_OinT = read_vec(t.at("p_OinT"));
      const JsonValue& q = t.at("q_OtoT");
      if (q.size() != 4) throw std::runtime_error("q_OtoT: expected 4 numbers");
      Eigen::Vector4d qv;
      for (std::size_t k = 0; k < 4; ++k) qv(static_cast<int>(k)) = q.at(k).number();
      tt.truth.R_OtoT = quat_to_rot(quat_normalize(qv));
      out.push_back(tt);
    }
    return out;
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + summary_json + "': " + e.what());
  }
}

ScaleFigures read_scale_figures(const std::string& summary_json, std::size_t run) {
  try {
    const JsonValue doc = JsonValue::parse(read_text_file(summary_json));
    const JsonValue& r = run_object(doc, run);
    ScaleFigures f;
    f.estimates = static_cast<int64_t>(r.at("estimates").number());
    f.accepted = static_cast<int64_t>(r.at("accepted").number());
    f.final_scale_error = r.at("final_scale_error").number();
    f.position_error.mean = read_vec(r.at("position_error_mean_m"));
    f.position_error.std = read_vec(r.at("position_error_std_m"));
    f.orientation_error.mean = read_vec(r.at("ypr_error_mean_rad"));
    f.orientation_error.std = read_vec(r.at("ypr_error_std_rad"));
    f.filtered_position_error.mean = read_vec(r.at("filtered_position_error_mean_m"));
    f.filtered_position_error.std = read_vec(r.at("filtered_position_error_std_m"));
    f.filtered_orientation_error.mean = read_vec(r.at("filtered_ypr_error_mean_rad"));
    f.filtered_orientation_error.std = read_vec(r.at("filtered_ypr_error_std_rad"));
    f.filtered_nees_position = r.at("filtered_nees_position").number();
    f.filtered_nees_orientation = r.at("filtered_nees_orientation").number();
    return f;
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + summary_json + "': " + e.what());
  }
}

}  // namespace eval
}  // namespace vimot

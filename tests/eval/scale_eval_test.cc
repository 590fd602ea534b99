// The figures of vimot-scale-eval (common/eval/scale_eval.h) against values
// derived by hand: the metric object pose error in G and its yaw/pitch/roll,
// scale errors per track, mean / std per axis, the median / max of |e|, and
// the tracks' truth through summary.json (what vimot-log-eval reads back).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>

#include "common/eval/json.h"
#include "common/eval/scale_eval.h"
#include "common/eval/writers.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::eval;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

ObjectTruth truth_a() {
  ObjectTruth t;
  t.s_true = 2.0;
  t.R_OtoT = exp_so3(Eigen::Vector3d(0.1, -0.2, 0.3));
  t.p_OinT = Eigen::Vector3d(0.1, 0.05, -0.02);
  return t;
}

}  // namespace

TEST_CASE("metric pose error: position in G and yaw / pitch / roll of the rotation error", "[eval][scale]") {
  const ObjectTruth t = truth_a();
  const Eigen::Matrix3d R_TtoG = exp_so3(Eigen::Vector3d(0.0, 0.0, 1.2));
  const Eigen::Vector3d p_TinG(3.0, -1.0, 0.2);
  const Eigen::Matrix3d R_OtoG_true = R_TtoG * t.R_OtoT;
  const Eigen::Vector3d p_OinG_true = R_TtoG * t.p_OinT + p_TinG;
  // Estimate: 0.01 yaw about G's z on top of the truth, 2 cm off in x.
  const Eigen::Matrix3d R_err = exp_so3(Eigen::Vector3d(0.0, 0.0, 0.01));
  const MetricPoseSample m = metric_pose_error(7, 1.9, R_err * R_OtoG_true,
                                               p_OinG_true + Eigen::Vector3d(0.02, 0.0, 0.0), t, R_TtoG, p_TinG);
  CHECK(m.utime == 7);
  CHECK(m.scale_true == 2.0);
  CHECK((m.err_p - Eigen::Vector3d(0.02, 0.0, 0.0)).norm() < 1e-12);
  CHECK_THAT(m.err_ypr(0), WithinAbs(0.01, 1e-12));
  CHECK_THAT(m.err_ypr(1), WithinAbs(0.0, 1e-12));
  CHECK_THAT(m.err_ypr(2), WithinAbs(0.0, 1e-12));
  // Pitch (about y) and roll (about x) alone.
  CHECK_THAT(metric_pose_error(0, 1, exp_so3(Eigen::Vector3d(0, 0.02, 0)) * R_OtoG_true, p_OinG_true, t, R_TtoG, p_TinG)
                 .err_ypr(1),
             WithinAbs(0.02, 1e-12));
  CHECK_THAT(metric_pose_error(0, 1, exp_so3(Eigen::Vector3d(-0.03, 0, 0)) * R_OtoG_true, p_OinG_true, t, R_TtoG, p_TinG)
                 .err_ypr(2),
             WithinAbs(-0.03, 1e-12));
}

TEST_CASE("scale figures: per-track truth, mean / std per axis, |error| statistics", "[eval][scale]") {
  const MeanStd3 ms = mean_std3({Eigen::Vector3d(1, 0, 2), Eigen::Vector3d(3, 0, 2), Eigen::Vector3d(5, 0, 2)});
  CHECK((ms.mean - Eigen::Vector3d(3, 0, 2)).norm() < 1e-12);
  CHECK((ms.std - Eigen::Vector3d(2, 0, 0)).norm() < 1e-12);  // sample std of 1, 3, 5
  const AbsStats a = abs_stats({0.01, -0.03, 0.02, -0.005});
  CHECK_THAT(a.median, WithinAbs(0.015, 1e-15));
  CHECK_THAT(a.max, WithinAbs(0.03, 1e-15));

  ObjectTruth t1 = truth_a();
  ObjectTruth t2 = truth_a();
  t2.s_true = 4.0;
  ScaleFigureBuilder b;
  b.add_estimate(5, 1.0, true);  // before any track: no truth, not an error sample
  b.start_track(10, t1);
  b.add_estimate(20, 2.1, true);   // +5 %
  b.add_estimate(30, 9.0, false);  // rejected: counted only
  b.start_track(100, t2);
  b.add_estimate(110, 3.8, true);  // −5 %
  CHECK_THROWS_AS(b.start_track(50, t1), std::invalid_argument);
  const ScaleFigures f = b.figures();
  CHECK(f.estimates == 4);
  CHECK(f.accepted == 2);
  REQUIRE(f.accepted_scale_errors.size() == 2);
  CHECK_THAT(f.accepted_scale_errors[0], WithinAbs(0.05, 1e-12));
  CHECK_THAT(f.accepted_scale_errors[1], WithinAbs(-0.05, 1e-12));
  CHECK_THAT(f.final_scale_error, WithinAbs(-0.05, 1e-12));
  CHECK(std::isnan(ScaleFigureBuilder().figures().final_scale_error));
}

TEST_CASE("filtered object states: pose error as the metric poses', NEES of position and orientation",
          "[eval][scale]") {
  const ObjectTruth t = truth_a();
  const Eigen::Matrix3d R_TtoG = exp_so3(Eigen::Vector3d(0.0, 0.0, 0.7));
  const Eigen::Vector3d p_TinG(1.0, 2.0, 0.0);
  const Eigen::Matrix3d R_OtoG_true = R_TtoG * t.R_OtoT;
  // Estimate: 3 cm off along y of G (σ_y 1 cm: NEES 9) and R̂_GtoO = Exp(δθ) R_GtoO,true
  // with δθ = (0, 0, 0.02) rad in O (σ 0.01 rad: NEES 4).
  TargetStateEstimate s;
  s.utime = 2000;
  s.representation = TargetFrame::kGlobal;
  s.q_GtoT = rot_to_quat(exp_so3(Eigen::Vector3d(0, 0, 0.02)) * R_OtoG_true.transpose());
  s.p_TinG = R_TtoG * t.p_OinT + p_TinG + Eigen::Vector3d(0, 0.03, 0);
  s.covariance = Eigen::Matrix<double, 12, 12>::Identity() * 1e-4;
  ScaleFigureBuilder b;
  b.add_filtered_pose(s, 2.0, R_TtoG, p_TinG);  // before the track: ignored
  b.start_track(1000, t);
  b.add_filtered_pose(s, 2.0, R_TtoG, p_TinG);
  const ScaleFigures f = b.figures();
  REQUIRE(f.filtered_poses.size() == 1);
  CHECK((f.filtered_poses[0].error.err_p - Eigen::Vector3d(0, 0.03, 0)).norm() < 1e-12);
  CHECK(f.filtered_poses[0].error.scale == 2.0);
  CHECK_THAT(f.filtered_nees_position, WithinRel(9.0, 1e-9));
  CHECK_THAT(f.filtered_nees_orientation, WithinRel(4.0, 1e-9));
  CHECK(f.metric_poses.empty());
}

TEST_CASE("scale summary.json: the tracks' truth and the figures read back", "[eval][scale]") {
  ScaleRunResult r;
  r.sim_seed = 3;
  r.tracks.push_back(TrackTruth{1, 1000, truth_a()});
  ScaleFigureBuilder b;
  b.start_track(1000, truth_a());
  b.add_estimate(2000, 2.02, true);
  const Eigen::Matrix3d R_TtoG = Eigen::Matrix3d::Identity();
  b.add_metric_pose(2000, 2.02, truth_a().R_OtoT, truth_a().p_OinT + Eigen::Vector3d(0.01, 0, 0), R_TtoG,
                    Eigen::Vector3d::Zero());
  b.add_metric_pose(2050, 2.02, truth_a().R_OtoT, truth_a().p_OinT + Eigen::Vector3d(0.03, 0, 0), R_TtoG,
                    Eigen::Vector3d::Zero());
  TargetStateEstimate s;
  s.utime = 2000;
  s.q_GtoT = rot_to_quat(truth_a().R_OtoT.transpose());
  s.p_TinG = truth_a().p_OinT + Eigen::Vector3d(0, 0.02, 0);
  s.covariance = Eigen::Matrix<double, 12, 12>::Identity() * 1e-4;  // NEES position 4
  b.add_filtered_pose(s, 2.02, R_TtoG, Eigen::Vector3d::Zero());
  s.utime = 2050;
  s.p_TinG = truth_a().p_OinT;
  b.add_filtered_pose(s, 2.02, R_TtoG, Eigen::Vector3d::Zero());
  r.figures = b.figures();
  JsonWriter j;
  j.begin_object().key("per_run").begin_array();
  write_scale_run_json(j, r);
  j.end_array().end_object();
  const std::string path = "/tmp/vimot_scale_eval_test_summary.json";
  write_text_file(path, j.str());
  const std::vector<TrackTruth> tracks = read_track_truths(path, 0);
  REQUIRE(tracks.size() == 1);
  CHECK(tracks[0].track_id == 1);
  CHECK(tracks[0].start_utime == 1000);
  CHECK(tracks[0].truth.s_true == 2.0);
  CHECK((tracks[0].truth.p_OinT - truth_a().p_OinT).norm() < 1e-12);
  CHECK((tracks[0].truth.R_OtoT - truth_a().R_OtoT).norm() < 1e-12);
  const ScaleFigures f = read_scale_figures(path, 0);
  CHECK(f.accepted == 1);
  CHECK_THAT(f.final_scale_error, WithinAbs(0.01, 1e-12));
  CHECK_THAT(f.position_error.mean(0), WithinAbs(0.02, 1e-12));
  CHECK_THAT(f.position_error.std(0), WithinAbs(std::sqrt(2.0) * 0.01, 1e-12));
  CHECK_THAT(f.filtered_position_error.mean(1), WithinAbs(0.01, 1e-12));
  CHECK_THAT(f.filtered_position_error.std(1), WithinAbs(std::sqrt(2.0) * 0.01, 1e-12));
  CHECK_THAT(f.filtered_nees_position, WithinAbs(2.0, 1e-9));
  CHECK_THAT(f.filtered_nees_orientation, WithinAbs(0.0, 1e-9));
  CHECK_THROWS_AS(read_track_truths(path, 1), std::runtime_error);
  CHECK_THROWS_AS(read_track_truths("/nonexistent.json", 0), std::runtime_error);
  std::remove(path.c_str());
}

// vimot-log-eval: accuracy and consistency of a recorded estimator run (an
// LCM log from lcm-logger or vimot-sim --log): the nav_state_t messages with
// updated = true against the ground_truth_t message of the same utime, with
// the same metrics as vimot-vio-eval. --compare prints the relative
// difference to an offline run's summary.json.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "common/eval/json.h"
#include "common/eval/log_eval.h"
#include "common/eval/writers.h"
#include "common/process/arg_parser.h"
#include "common/process/process.h"

namespace {

using namespace vimot;

double relative_difference(double a, double b) {
  if (a == b) return 0.0;
  return std::fabs(a - b) / std::max(std::fabs(b), 1e-300);
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-log-eval",
                 "Evaluates an estimator's states in an LCM log against the ground truth in the same\n"
                 "log: states with updated = true, truth at exactly the same utime. Prints position\n"
                 "RMSE [m], orientation RMSE [deg], average NEES of position and orientation (ideal 3)\n"
                 "and the sample count. Malformed messages are counted and skipped.\n"
                 "With --target-channel also the target filter's target_state_t: the target pose in\n"
                 "the IMU frame and in the world (NEES only in the filter's representation: the log\n"
                 "carries only that covariance).\n"
                 "Exit status: 0; 2 if no state could be matched; 3 if --tolerance is exceeded;\n"
                 "1 on bad input.");
  args.set_positional("LOG", "LCM log file", 1, 1);
  args.add_option("state-channel", "CHANNEL", "nav_state_t channel", "VINS_STATE");
  args.add_option("truth-channel", "CHANNEL", "ground_truth_t channel", "GROUND_TRUTH");
  args.add_option("target-channel", "CHANNEL", "target_state_t channel to evaluate too (e.g. TARGET_STATE)");
  args.add_flag("own-target-frame",
                "with --target-channel: the filter started its target from its features (target.init.mode\n"
                "features), so its target frame is its own: compare through the fixed transform to the true\n"
                "frame taken at its first target state (printed), and again at the first state of each new\n"
                "start (its start_count changed: the filter started the target again)");
  args.add_option("target-restart-gap", "SECONDS",
                  "with --own-target-frame: target states more than SECONDS apart mean the filter started its\n"
                  "target again (a respawned process, a reset) in a new frame of its own, taken again at its\n"
                  "first state after the gap (default: only where start_count changes)");
  args.add_option("from-utime", "UTIME",
                  "evaluate only the states (and target states) at or after this utime, e.g. those of a\n"
                  "process restarted mid-run (its \"initialised from ground truth at utime N\")");
  args.add_option("compare-target", "SUMMARY_JSON",
                  "with --target-channel: print the relative difference of the target figures, and of the\n"
                  "robot's on --state-channel (the target filter's NAV_STATE: moved by the target unless skf),\n"
                  "to a one-run vimot-target-eval summary.json (its first target-filter cell)");
  args.add_option("scale-truth", "SUMMARY_JSON",
                  "evaluate the monocular scale pipeline too: SCALE_ESTIMATE, OBJECT_POSE_METRIC and OBJECT_STATE\n"
                  "against the truth of the object tracks in this one-run vimot-scale-eval summary.json\n"
                  "of the same seed (the log cannot define the tracker's object frame), and print the\n"
                  "relative difference to that run's figures");
  args.add_option("scale-channel", "CHANNEL", "scale_estimate_t channel", "SCALE_ESTIMATE");
  args.add_option("metric-channel", "CHANNEL", "metric_object_pose_t channel", "OBJECT_POSE_METRIC");
  args.add_option("object-state-channel", "CHANNEL", "target_state_t channel of the object motion filter",
                  "OBJECT_STATE");
  args.add_option("box-channel", "CHANNEL",
                  "target_box_t channel of the mask filter (e.g. TARGET_BOX): per camera, the frames with a\n"
                  "valid filtered box and its IoU with the rendered simulator's true box of the same image");
  args.add_option("box-truth-channel", "CHANNEL", "with --box-channel: the true boxes", "TARGET_BOX_TRUTH");
  args.add_option("json", "FILE", "write the summary as JSON (object \"summary\", as vimot-vio-eval's)");
  args.add_option("csv", "FILE", "write the per-sample errors with 3-sigma bounds (as vimot-vio-eval's)");
  args.add_option("compare", "SUMMARY_JSON", "print the relative difference to this summary (e.g. an offline run)");
  args.add_option("tolerance", "REL", "with --compare: exit 3 if a relative difference exceeds REL");
  if (!args.parse(argc, argv)) return 0;
  const std::string path = args.positionals()[0];

  eval::LogEvalOptions opt;
  opt.state_channel = args.get("state-channel");
  opt.truth_channel = args.get("truth-channel");
  opt.target_channel = args.get("target-channel");
  opt.target_own_frame = args.given("own-target-frame");
  if (args.given("target-restart-gap")) {
    if (!opt.target_own_frame) throw ArgError("vimot-log-eval: --target-restart-gap needs --own-target-frame");
    opt.target_restart_gap_s = args.get_double("target-restart-gap");
    if (!(opt.target_restart_gap_s > 0.0)) throw ArgError("vimot-log-eval: --target-restart-gap must be > 0");
  }
  if (args.given("from-utime")) {
    opt.from_utime = args.get_int("from-utime");
    if (opt.from_utime < 0) throw ArgError("vimot-log-eval: --from-utime must be >= 0");
  }
  if (args.given("scale-truth")) {
    opt.scale_channel = args.get("scale-channel");
    opt.metric_channel = args.get("metric-channel");
    opt.object_state_channel = args.get("object-state-channel");
    opt.tracks = eval::read_track_truths(args.get("scale-truth"), 0);
  }
  if (args.given("box-channel")) {
    opt.box_channel = args.get("box-channel");
    opt.box_truth_channel = args.get("box-truth-channel");
  }
  if (args.given("compare-target") && opt.target_channel.empty()) {
    throw ArgError("--compare-target needs --target-channel");
  }
  const eval::LogEvalResult r = eval::evaluate_log(path, opt);
  const eval::MatchCounts& c = r.counts;

  std::printf("log: %s (%lld events)\n", path.c_str(), static_cast<long long>(r.events));
  std::printf("states on %s: %lld (updated %lld, duplicate %lld, malformed %lld)\n", opt.state_channel.c_str(),
              static_cast<long long>(c.states), static_cast<long long>(c.updated_states),
              static_cast<long long>(c.duplicate_states), static_cast<long long>(r.malformed_states));
  std::printf("truth on %s: %lld (duplicate %lld, malformed %lld)\n", opt.truth_channel.c_str(),
              static_cast<long long>(c.truths), static_cast<long long>(c.duplicate_truths),
              static_cast<long long>(r.malformed_truths));
  std::printf("matched %lld, without truth %lld, covariance not positive definite %lld\n",
              static_cast<long long>(c.matched), static_cast<long long>(c.unmatched),
              static_cast<long long>(c.bad_covariance));
  if (!r.first_malformed.empty()) std::printf("first malformed message: %s\n", r.first_malformed.c_str());
  const eval::ErrorSummary& s = r.summary;
  std::printf("samples %lld  position RMSE %.4f m  orientation RMSE %.4f deg  NEES position %.2f  orientation %.2f\n",
              static_cast<long long>(s.count), s.rmse_position_m, s.rmse_orientation_deg, s.nees_position,
              s.nees_orientation);

  if (args.given("json")) {
    eval::JsonWriter j;
    j.begin_object();
    j.field("tool", "vimot-log-eval").field("log", path);
    j.field("state_channel", opt.state_channel).field("truth_channel", opt.truth_channel);
    j.key("summary");
    eval::write_summary_json(j, s);
    j.key("counts").begin_object();
    j.field("events", r.events).field("states", c.states).field("updated_states", c.updated_states);
    j.field("duplicate_states", c.duplicate_states).field("malformed_states", r.malformed_states);
    j.field("truths", c.truths).field("duplicate_truths", c.duplicate_truths);
    j.field("malformed_truths", r.malformed_truths).field("matched", c.matched).field("unmatched", c.unmatched);
    j.field("bad_covariance", c.bad_covariance);
    j.end_object();
    j.end_object();
    eval::write_text_file(args.get("json"), j.str());
  }
  if (args.given("csv")) eval::write_errors_csv(args.get("csv"), r.samples);

  if (!opt.target_channel.empty()) {
    const eval::TargetMatchCounts& tc = r.target_counts;
    std::printf("target states on %s: %lld (duplicate %lld, malformed %lld), matched %lld, without truth %lld, "
                "covariance not positive definite %lld\n",
                opt.target_channel.c_str(), static_cast<long long>(tc.states),
                static_cast<long long>(tc.duplicate_states), static_cast<long long>(r.malformed_targets),
                static_cast<long long>(tc.matched), static_cast<long long>(tc.unmatched),
                static_cast<long long>(tc.bad_covariance));
    std::printf("target kept: %lld of %lld updated states from the first target state on have one\n",
                static_cast<long long>(r.frames_with_target), static_cast<long long>(r.frames_since_target_start));
    if (opt.target_own_frame) {
      std::printf("target frame (filter's in the true one, taken at its first state and at each new start; the "
                  "last): %s\n",
                  r.target_samples.target_frame.describe().c_str());
      std::printf("target started again (start_count changed");
      if (opt.target_restart_gap_s > 0.0) std::printf(", or gaps above %.3g s", opt.target_restart_gap_s);
      std::printf("): %lld times, the frame taken again at each\n",
                  static_cast<long long>(r.target_samples.frame_restarts));
    }
    for (const auto& [name, ts] : {std::pair<const char*, const eval::ErrorSummary&>{"in IMU  ", r.target_in_imu},
                                   std::pair<const char*, const eval::ErrorSummary&>{"in world", r.target_in_world}}) {
      // TARGET_STATE carries the covariance of its representation only
      // (local: in IMU, global: in world); the other frame has no NEES.
      std::printf("target %s: position RMSE %.5f m  orientation RMSE %.4f deg  ", name, ts.rmse_position_m,
                  ts.rmse_orientation_deg);
      if (std::isnan(ts.nees_position)) {
        std::printf("NEES n/a (no covariance in this frame on the message)\n");
      } else {
        std::printf("NEES position %.2f  orientation %.2f\n", ts.nees_position, ts.nees_orientation);
      }
    }
  }

  for (std::size_t cam = 0; cam < r.boxes.size(); ++cam) {
    const eval::BoxCameraFigures& b = r.boxes[cam];
    if (b.truth_frames == 0 && b.boxes == 0) continue;
    std::printf("box camera %zu on %s: %lld boxes for %lld true (target visible %lld, no box %lld, malformed %lld); "
                "kept %lld of %lld visible, filtered valid %lld, detections %lld, box without target %lld, "
                "longest coast %d frames; IoU with the truth mean %.3f min %.3f (< 0.5: %lld)\n",
                cam, opt.box_channel.c_str(), static_cast<long long>(b.boxes), static_cast<long long>(b.truth_frames),
                static_cast<long long>(b.truth_visible), static_cast<long long>(b.missing),
                static_cast<long long>(r.malformed_boxes), static_cast<long long>(b.kept),
                static_cast<long long>(b.truth_visible), static_cast<long long>(b.filtered_valid),
                static_cast<long long>(b.raw_valid), static_cast<long long>(b.false_boxes), b.max_coasted, b.mean_iou,
                b.min_iou, static_cast<long long>(b.low_iou));
  }
  if (!opt.scale_channel.empty()) {
    const eval::ScaleFigures& f = r.scale;
    const eval::AbsStats a = eval::abs_stats(f.accepted_scale_errors);
    std::printf("scale estimates on %s: %lld (accepted %lld, malformed %lld); scale error median %.2f %%, max %.2f %%, "
                "last accepted %.2f %%\n",
                opt.scale_channel.c_str(), static_cast<long long>(f.estimates), static_cast<long long>(f.accepted),
                static_cast<long long>(r.malformed_scale), 100.0 * a.median, 100.0 * a.max,
                100.0 * f.final_scale_error);
    std::printf("metric object poses on %s: %lld (without truth %lld); position error std %.4f / %.4f / %.4f m, "
                "yaw/pitch/roll std %.4f / %.4f / %.4f rad\n",
                opt.metric_channel.c_str(), static_cast<long long>(f.metric_poses.size()),
                static_cast<long long>(r.metric_without_truth), f.position_error.std(0), f.position_error.std(1),
                f.position_error.std(2), f.orientation_error.std(0), f.orientation_error.std(1),
                f.orientation_error.std(2));
    std::printf("filtered object states on %s: %lld (without truth %lld); position error std %.4f / %.4f / %.4f m, "
                "yaw/pitch/roll std %.4f / %.4f / %.4f rad, NEES position %.2f, orientation %.2f\n",
                opt.object_state_channel.c_str(), static_cast<long long>(f.filtered_poses.size()),
                static_cast<long long>(r.object_states_without_truth), f.filtered_position_error.std(0),
                f.filtered_position_error.std(1), f.filtered_position_error.std(2),
                f.filtered_orientation_error.std(0), f.filtered_orientation_error.std(1),
                f.filtered_orientation_error.std(2), f.filtered_nees_position, f.filtered_nees_orientation);
  }

  int status = s.count > 0 ? 0 : 2;
  if (!opt.target_channel.empty() && r.target_in_imu.count == 0) status = 2;
  const double tol = args.given("tolerance") ? args.get_double("tolerance") : -1.0;
  struct Row {
    const char* name;
    double log, offline;
  };
  auto print_compare = [&](const std::string& reference, const std::vector<Row>& rows) {
    std::printf("compare with %s:\n  %-32s %14s %14s %12s\n", reference.c_str(), "", "this log", "reference",
                "rel. diff");
    for (const Row& row : rows) {
      if (std::isnan(row.log) && std::isnan(row.offline)) continue;
      const double d = relative_difference(row.log, row.offline);
      std::printf("  %-32s %14.6g %14.6g %12.3e%s\n", row.name, row.log, row.offline, d,
                  tol >= 0.0 && d > tol ? "  > tolerance" : "");
      if (tol >= 0.0 && !(d <= tol)) status = 3;
    }
  };
  if (args.given("compare")) {
    const eval::ErrorSummary o = eval::read_summary_json(args.get("compare"));
    print_compare(args.get("compare"),
                  {{"position RMSE [m]", s.rmse_position_m, o.rmse_position_m},
                   {"orientation RMSE [deg]", s.rmse_orientation_deg, o.rmse_orientation_deg},
                   {"NEES position", s.nees_position, o.nees_position},
                   {"NEES orientation", s.nees_orientation, o.nees_orientation},
                   {"samples", static_cast<double>(s.count), static_cast<double>(o.count)}});
  }
  if (args.given("compare-target")) {
    const std::string ref = args.get("compare-target");
    const std::string cell = "cells/" + std::to_string(eval::first_target_cell_index(ref)) + "/per_run/0/";
    const eval::ErrorSummary oi = eval::read_summary_json(ref, cell + "target_in_imu");
    const eval::ErrorSummary ow = eval::read_summary_json(ref, cell + "target_in_world");
    const eval::ErrorSummary orobot = eval::read_summary_json(ref, cell + "imu");
    const eval::ErrorSummary& li = r.target_in_imu;
    const eval::ErrorSummary& lw = r.target_in_world;
    const bool local = std::isnan(lw.nees_position);  // NEES only in the filter's representation
    const eval::ErrorSummary& ln = local ? li : lw;
    const eval::ErrorSummary& on = local ? oi : ow;
    print_compare(ref, {{"target in IMU position RMSE [m]", li.rmse_position_m, oi.rmse_position_m},
                        {"target in IMU orientation [deg]", li.rmse_orientation_deg, oi.rmse_orientation_deg},
                        {"target in world position [m]", lw.rmse_position_m, ow.rmse_position_m},
                        {"target in world orientation [deg]", lw.rmse_orientation_deg, ow.rmse_orientation_deg},
                        {"target NEES position", ln.nees_position, on.nees_position},
                        {"target NEES orientation", ln.nees_orientation, on.nees_orientation},
                        {"target samples", static_cast<double>(li.count), static_cast<double>(oi.count)},
                        {"robot position RMSE [m]", s.rmse_position_m, orobot.rmse_position_m},
                        {"robot orientation RMSE [deg]", s.rmse_orientation_deg, orobot.rmse_orientation_deg},
                        {"robot NEES position", s.nees_position, orobot.nees_position},
                        {"robot NEES orientation", s.nees_orientation, orobot.nees_orientation},
                        {"robot samples", static_cast<double>(s.count), static_cast<double>(orobot.count)}});
  }
  if (!opt.scale_channel.empty()) {
    const eval::ScaleFigures o = eval::read_scale_figures(args.get("scale-truth"), 0);
    const eval::ScaleFigures& f = r.scale;
    print_compare(args.get("scale-truth"),
                  {{"scale estimates", static_cast<double>(f.estimates), static_cast<double>(o.estimates)},
                   {"accepted estimates", static_cast<double>(f.accepted), static_cast<double>(o.accepted)},
                   {"last accepted scale error", f.final_scale_error, o.final_scale_error},
                   {"object position std x [m]", f.position_error.std(0), o.position_error.std(0)},
                   {"object position std y [m]", f.position_error.std(1), o.position_error.std(1)},
                   {"object position std z [m]", f.position_error.std(2), o.position_error.std(2)},
                   {"object yaw std [rad]", f.orientation_error.std(0), o.orientation_error.std(0)},
                   {"object pitch std [rad]", f.orientation_error.std(1), o.orientation_error.std(1)},
                   {"object roll std [rad]", f.orientation_error.std(2), o.orientation_error.std(2)},
                   {"filtered position std x [m]", f.filtered_position_error.std(0), o.filtered_position_error.std(0)},
                   {"filtered position std y [m]", f.filtered_position_error.std(1), o.filtered_position_error.std(1)},
                   {"filtered position std z [m]", f.filtered_position_error.std(2), o.filtered_position_error.std(2)},
                   {"filtered yaw std [rad]", f.filtered_orientation_error.std(0),
                    o.filtered_orientation_error.std(0)},
                   {"filtered pitch std [rad]", f.filtered_orientation_error.std(1),
                    o.filtered_orientation_error.std(1)},
                   {"filtered roll std [rad]", f.filtered_orientation_error.std(2),
                    o.filtered_orientation_error.std(2)},
                   {"filtered NEES position", f.filtered_nees_position, o.filtered_nees_position},
                   {"filtered NEES orientation", f.filtered_nees_orientation, o.filtered_nees_orientation}});
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

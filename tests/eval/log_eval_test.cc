// vimot-log-eval on logs this test writes with lcm::LogFile: known errors
// give known RMSE/NEES; only updated states count; truth matched by exact
// utime; corrupt and non-finite messages counted, never fatal. And an
// offline run pushed through the LCM messages gives the same summary as
// run_vio_on_sim (the LCM run == offline run check, on the evaluation side).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "common/config/config.h"
#include "common/estimator/nav_state_of.h"
#include "common/estimator/vins_config.h"
#include "common/eval/json.h"
#include "common/eval/log_eval.h"
#include "common/eval/sim_runner.h"
#include "common/eval/writers.h"
#include "common/math/quat.h"
#include "common/process/lcm_conversions.h"
#include "procs/eval/vio_run.h"

using namespace vimot;
using namespace vimot::eval;
using estimator::load_vio_options;
using estimator::nav_state_of;
using Catch::Matchers::WithinAbs;
using Catch::Matchers::WithinRel;

namespace {

std::string temp_path(const char* stem) {
  char name[64];
  std::snprintf(name, sizeof(name), "/tmp/vimot_logeval_%s_XXXXXX", stem);
  const int fd = mkstemp(name);
  REQUIRE(fd >= 0);
  close(fd);
  return name;
}

class LogWriter {
 public:
  explicit LogWriter(const std::string& path) : log_(path, "w") { REQUIRE(log_.good()); }

  template <typename Msg>
  void write(const std::string& channel, const Msg& msg, int64_t utime) {
    std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
    REQUIRE(msg.encode(buf.data(), 0, static_cast<int>(buf.size())) == static_cast<int>(buf.size()));
    raw(channel, buf, utime);
  }
  void raw(const std::string& channel, std::vector<uint8_t> bytes, int64_t utime) {
    lcm::LogEvent ev;
    ev.eventnum = n_++;
    ev.timestamp = utime;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(bytes.size());
    ev.data = bytes.data();
    REQUIRE(log_.writeEvent(&ev) == 0);
  }

 private:
  lcm::LogFile log_;
  int64_t n_{0};
};

GroundTruth truth_at(int64_t utime) {
  GroundTruth gt;
  gt.utime = utime;
  gt.p_IinG = Eigen::Vector3d(0.01 * static_cast<double>(utime), 1.0, 2.0);
  gt.q_GtoI = rot_to_quat(exp_so3(Eigen::Vector3d(0.1, 0.2, 0.001 * static_cast<double>(utime))));
  return gt;
}

// A state with position error err_p (truth − estimate) and orientation error
// err_theta, covariance σ_p² I and σ_θ² I.
NavState state_at(int64_t utime, const Eigen::Vector3d& err_p, const Eigen::Vector3d& err_theta, double sigma_p,
                  double sigma_theta, bool updated = true) {
  const GroundTruth gt = truth_at(utime);
  NavState s;
  s.utime = utime;
  s.updated = updated;
  s.p_IinG = gt.p_IinG - err_p;
  // truth = est ⊞ err  ->  est = Exp(err) R_true
  s.q_GtoI = rot_to_quat(exp_so3(err_theta) * quat_to_rot(gt.q_GtoI));
  s.covariance = Eigen::Matrix<double, 15, 15>::Identity();
  s.covariance.block<3, 3>(0, 0) = sigma_theta * sigma_theta * Eigen::Matrix3d::Identity();
  s.covariance.block<3, 3>(3, 3) = sigma_p * sigma_p * Eigen::Matrix3d::Identity();
  return s;
}

int run_command(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("Log evaluation: known errors, updated states only, corrupt messages counted", "[eval][log]") {
  const std::string path = temp_path("log");
  {
    LogWriter w(path);
    for (int64_t t = 100; t <= 400; t += 100) w.write("GROUND_TRUTH", to_lcm(truth_at(t)), t);
    w.write("GROUND_TRUTH", to_lcm(truth_at(100)), 100);  // duplicate truth
    // Updated states with errors |δp| = 0.3 and 0.4 m, |δθ| = 0.01 rad.
    w.write("VINS_STATE", to_lcm(state_at(100, Eigen::Vector3d(0.3, 0, 0), Eigen::Vector3d(0.01, 0, 0), 0.1, 0.01)),
            100);
    w.write("VINS_STATE", to_lcm(state_at(150, Eigen::Vector3d(9, 9, 9), Eigen::Vector3d(1, 0, 0), 0.1, 0.01, false)),
            150);  // propagation only: ignored
    w.write("VINS_STATE", to_lcm(state_at(200, Eigen::Vector3d(0, 0.4, 0), Eigen::Vector3d(0, 0, 0.01), 0.2, 0.02)),
            200);
    w.write("VINS_STATE", to_lcm(state_at(250, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d::Zero(), 1, 1)),
            250);  // no truth at 250: unmatched
    w.raw("VINS_STATE", {0xde, 0xad, 0xbe, 0xef, 1, 2, 3}, 260);  // corrupt
    nav_state_t nan_state = to_lcm(state_at(300, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1, 1));
    nan_state.p_IinG[1] = std::nan("");
    w.write("VINS_STATE", nan_state, 300);                          // non-finite: malformed
    w.write("VINS_STATE", to_lcm(truth_at(350)), 350);              // wrong type on the channel
    w.write("OTHER", to_lcm(truth_at(400)), 400);                   // other channel: ignored
    w.raw("GROUND_TRUTH", {1, 2, 3}, 410);                          // corrupt truth
  }
  const LogEvalResult r = evaluate_log(path);
  CHECK(r.events == 14);
  CHECK(r.malformed_states == 3);
  CHECK(r.malformed_truths == 1);
  CHECK_FALSE(r.first_malformed.empty());
  CHECK(r.counts.states == 4);
  CHECK(r.counts.updated_states == 3);
  CHECK(r.counts.truths == 5);
  CHECK(r.counts.duplicate_truths == 1);
  CHECK(r.counts.matched == 2);
  CHECK(r.counts.unmatched == 1);
  REQUIRE(r.summary.count == 2);
  // RMSE_p = √((0.09 + 0.16)/2) = √0.125; RMSE_θ = 0.01 rad.
  CHECK_THAT(r.summary.rmse_position_m, WithinRel(std::sqrt(0.125), 1e-9));
  CHECK_THAT(r.summary.rmse_orientation_deg, WithinRel(0.01 * 180.0 / M_PI, 1e-9));
  // NEES_p: (0.3/0.1)² = 9 and (0.4/0.2)² = 4 -> 6.5; NEES_θ: 1 and 0.25 -> 0.625.
  CHECK_THAT(r.summary.nees_position, WithinRel(6.5, 1e-9));
  CHECK_THAT(r.summary.nees_orientation, WithinRel(0.625, 1e-9));
  REQUIRE(r.samples.size() == 2);
  CHECK(r.samples[0].utime == 100);
  CHECK((r.samples[0].err_p - Eigen::Vector3d(0.3, 0, 0)).norm() < 1e-12);

  LogEvalOptions other;
  other.state_channel = "NOPE";
  CHECK(evaluate_log(path, other).summary.count == 0);
  CHECK_THROWS_AS(evaluate_log("/nonexistent/log"), std::runtime_error);

  // The command line: prints, writes JSON, compares with itself.
  const std::string json = temp_path("json");
  const std::string bin = VIMOT_LOG_EVAL_BIN;
  CHECK(run_command(bin + " " + path + " --json " + json + " > /dev/null") == 0);
  const ErrorSummary s = read_summary_json(json);
  CHECK(s.count == 2);
  CHECK(s.rmse_position_m == r.summary.rmse_position_m);
  CHECK(run_command(bin + " " + path + " --compare " + json + " --tolerance 1e-12 > /dev/null") == 0);
  // Against a different reference: exit 3 beyond the tolerance.
  ErrorSummary other_summary = s;
  other_summary.rmse_position_m *= 1.1;
  JsonWriter j;
  j.begin_object().key("summary");
  write_summary_json(j, other_summary);
  j.end_object();
  write_text_file(json, j.str());
  CHECK(run_command(bin + " " + path + " --compare " + json + " --tolerance 0.01 > /dev/null") == 3);
  CHECK(run_command(bin + " " + path + " --state-channel NOPE > /dev/null") == 2);
  CHECK(run_command(bin + " /nonexistent/log > /dev/null 2>&1") == 1);
  std::remove(json.c_str());
  std::remove(path.c_str());
}

TEST_CASE("Log evaluation of target states: both frames, NEES in the filter's representation", "[eval][log]") {
  // Truth: robot at truth_at(t), target 5 m ahead in I, yawed by 0.3 rad.
  auto truth_with_target = [](int64_t utime) {
    GroundTruth gt = truth_at(utime);
    gt.has_target = true;
    const Eigen::Matrix3d R_GtoI = quat_to_rot(gt.q_GtoI);
    const Eigen::Matrix3d R_ItoT = exp_so3(Eigen::Vector3d(0, 0, 0.3)).transpose();
    gt.q_GtoT = rot_to_quat(R_ItoT * R_GtoI);
    gt.p_TinG = gt.p_IinG + R_GtoI.transpose() * Eigen::Vector3d(5, 0, 0);
    return gt;
  };
  // A local estimate with errors (truth − estimate) err_p in I and err_theta
  // in T; the world pose derived with the true robot pose, so its errors are
  // err_p rotated into G and the same err_theta.
  auto target_at = [&](int64_t utime, const Eigen::Vector3d& err_p, const Eigen::Vector3d& err_theta, double sigma) {
    const GroundTruth gt = truth_with_target(utime);
    const eval::TargetInImu t = true_target_in_imu(gt);
    TargetStateEstimate e;
    e.utime = utime;
    e.representation = TargetFrame::kLocal;
    e.p_TinI = t.p_TinI - err_p;
    e.q_ItoT = rot_to_quat(exp_so3(err_theta) * quat_to_rot(t.q_ItoT));
    const Eigen::Matrix3d R_GtoI = quat_to_rot(gt.q_GtoI);
    e.p_TinG = gt.p_IinG + R_GtoI.transpose() * e.p_TinI;
    e.q_GtoT = rot_to_quat(quat_to_rot(e.q_ItoT) * R_GtoI);
    e.covariance = sigma * sigma * Eigen::Matrix<double, 12, 12>::Identity();
    return e;
  };
  const std::string path = temp_path("target");
  {
    LogWriter w(path);
    for (int64_t t = 100; t <= 300; t += 100) w.write("GROUND_TRUTH", to_lcm(truth_with_target(t)), t);
    w.write("GROUND_TRUTH", to_lcm(truth_at(400)), 400);  // no target in the truth
    w.write("TARGET_STATE", to_lcm(target_at(100, Eigen::Vector3d(0.03, 0, 0), Eigen::Vector3d(0, 0, 0.02), 0.01)), 100);
    w.write("TARGET_STATE", to_lcm(target_at(200, Eigen::Vector3d(0, 0, 0.04), Eigen::Vector3d(0.02, 0, 0), 0.02)), 200);
    w.write("TARGET_STATE", to_lcm(target_at(200, Eigen::Vector3d(1, 1, 1), Eigen::Vector3d::Zero(), 1)), 200);  // dup
    w.write("TARGET_STATE", to_lcm(target_at(400, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1)), 400);
    w.raw("TARGET_STATE", {1, 2, 3, 4}, 410);  // corrupt
  }
  LogEvalOptions o;
  o.target_channel = "TARGET_STATE";
  const LogEvalResult r = evaluate_log(path, o);
  CHECK(r.malformed_targets == 1);
  CHECK(r.target_counts.states == 4);
  CHECK(r.target_counts.duplicate_states == 1);
  CHECK(r.target_counts.matched == 2);
  CHECK(r.target_counts.unmatched == 1);
  REQUIRE(r.target_in_imu.count == 2);
  REQUIRE(r.target_in_world.count == 2);
  // RMSE_p = √((0.03² + 0.04²)/2) = 0.025·√2; RMSE_θ = 0.02 rad; in both frames.
  CHECK_THAT(r.target_in_imu.rmse_position_m, WithinRel(0.025 * std::sqrt(2.0), 1e-9));
  CHECK_THAT(r.target_in_world.rmse_position_m, WithinRel(0.025 * std::sqrt(2.0), 1e-9));
  CHECK_THAT(r.target_in_imu.rmse_orientation_deg, WithinRel(0.02 * 180.0 / M_PI, 1e-9));
  CHECK_THAT(r.target_in_world.rmse_orientation_deg, WithinRel(0.02 * 180.0 / M_PI, 1e-9));
  // NEES_p: 9 and 4; NEES_θ: 4 and 1 — in I only; the world frame has no covariance.
  CHECK_THAT(r.target_in_imu.nees_position, WithinRel(6.5, 1e-9));
  CHECK_THAT(r.target_in_imu.nees_orientation, WithinRel(2.5, 1e-9));
  CHECK(std::isnan(r.target_in_world.nees_position));
  // Without --target-channel nothing of it is evaluated.
  CHECK(evaluate_log(path).target_in_imu.count == 0);
  std::remove(path.c_str());
}

TEST_CASE("Log evaluation of the scale pipeline: estimates and metric poses against the tracks' truth",
          "[eval][log]") {
  // Target at p_TinG = (t, 0, 0) m (t in ms), yawed 0.2 rad; object frame O
  // at p_OinT = (0.1, 0, 0) with R_OtoT = I; s_true = 2.
  auto truth_with_target = [](int64_t utime) {
    GroundTruth gt = truth_at(utime);
    gt.has_target = true;
    gt.q_GtoT = rot_to_quat(exp_so3(Eigen::Vector3d(0, 0, 0.2)).transpose());
    gt.p_TinG = Eigen::Vector3d(1e-3 * static_cast<double>(utime), 0, 0);
    return gt;
  };
  TrackTruth track;
  track.track_id = 1;
  track.start_utime = 100;
  track.truth.s_true = 2.0;
  track.truth.p_OinT = Eigen::Vector3d(0.1, 0, 0);
  auto metric_at = [&](int64_t utime, const Eigen::Vector3d& err_p, double yaw_err) {
    const GroundTruth gt = truth_with_target(utime);
    const Eigen::Matrix3d R_TtoG = quat_to_rot(gt.q_GtoT).transpose();
    scale::ObjectPoseInWorld p;
    p.utime = utime;
    p.scale = 2.1;
    p.R_OtoG = exp_so3(Eigen::Vector3d(0, 0, yaw_err)) * R_TtoG;
    p.q_GtoO = rot_to_quat(p.R_OtoG.transpose());
    p.p_OinG = R_TtoG * track.truth.p_OinT + gt.p_TinG + err_p;
    return to_lcm(p);
  };
  auto estimate_at = [](int64_t utime, double scale, bool accepted) {
    scale::ScaleResult r;
    r.utime = utime;
    r.scale = scale;
    r.accepted = accepted;
    return to_lcm(r);
  };
  const std::string path = temp_path("scale");
  {
    LogWriter w(path);
    for (int64_t t = 100; t <= 400; t += 100) w.write("GROUND_TRUTH", to_lcm(truth_with_target(t)), t);
    w.write("SCALE_ESTIMATE", estimate_at(50, 5.0, true), 50);    // before the track: no truth
    w.write("SCALE_ESTIMATE", estimate_at(200, 2.1, true), 200);  // +5 %
    w.write("SCALE_ESTIMATE", estimate_at(300, 9.0, false), 300);
    w.write("OBJECT_POSE_METRIC", metric_at(200, Eigen::Vector3d(0.01, 0, 0), 0.01), 200);
    w.write("OBJECT_POSE_METRIC", metric_at(300, Eigen::Vector3d(0.03, 0, 0), 0.03), 300);
    w.write("OBJECT_POSE_METRIC", metric_at(350, Eigen::Vector3d::Zero(), 0.0), 350);  // no truth at 350
    w.raw("OBJECT_POSE_METRIC", {1, 2, 3}, 360);                                       // corrupt
    // Filtered states: at 200 2 cm off in y (σ 1 cm: NEES 4), at 300 exact; at 250 no metric pose.
    for (const auto& [t, dy] : {std::pair<int64_t, double>{200, 0.02}, {250, 0.0}, {300, 0.0}}) {
      const GroundTruth gt = truth_with_target(t);
      const Eigen::Matrix3d R_TtoG = quat_to_rot(gt.q_GtoT).transpose();
      TargetStateEstimate s;
      s.utime = t;
      s.representation = TargetFrame::kGlobal;
      s.q_GtoT = gt.q_GtoT;
      s.p_TinG = R_TtoG * track.truth.p_OinT + gt.p_TinG + Eigen::Vector3d(0, dy, 0);
      s.covariance = Eigen::Matrix<double, 12, 12>::Identity() * 1e-4;
      w.write("OBJECT_STATE", to_lcm(s), t);
    }
  }
  LogEvalOptions o;
  o.scale_channel = "SCALE_ESTIMATE";
  o.metric_channel = "OBJECT_POSE_METRIC";
  o.object_state_channel = "OBJECT_STATE";
  o.tracks = {track};
  const LogEvalResult r = evaluate_log(path, o);
  CHECK(r.malformed_scale == 1);
  CHECK(r.metric_without_truth == 1);
  CHECK(r.scale.estimates == 3);
  CHECK(r.scale.accepted == 1);
  CHECK_THAT(r.scale.final_scale_error, WithinAbs(0.05, 1e-12));
  REQUIRE(r.scale.metric_poses.size() == 2);
  CHECK_THAT(r.scale.position_error.mean(0), WithinAbs(0.02, 1e-12));
  CHECK_THAT(r.scale.position_error.std(0), WithinAbs(std::sqrt(2.0) * 0.01, 1e-12));
  CHECK_THAT(r.scale.orientation_error.mean(0), WithinAbs(0.02, 1e-12));
  CHECK_THAT(r.scale.orientation_error.std(0), WithinAbs(std::sqrt(2.0) * 0.01, 1e-12));
  CHECK(r.object_states_without_truth == 1);
  REQUIRE(r.scale.filtered_poses.size() == 2);
  CHECK(r.scale.filtered_poses[0].error.scale == 2.1);
  CHECK_THAT(r.scale.filtered_position_error.mean(1), WithinAbs(0.01, 1e-12));
  CHECK_THAT(r.scale.filtered_nees_position, WithinAbs(2.0, 1e-6));
  CHECK_THAT(r.scale.filtered_nees_orientation, WithinAbs(0.0, 1e-9));
  std::remove(path.c_str());
}

TEST_CASE("An offline run through LCM messages evaluates identically", "[eval][log]") {
  const std::string src = VIMOT_SOURCE_DIR;
  sim::SimConfig cfg = sim::from_config(Config::load_file(src + "/config/sim_paper.yaml"));
  cfg.duration = 2.0;
  const estimator::VioOptions o = load_vio_options(src + "/config/vins.yaml");
  const std::string path = temp_path("run");
  SimRunResult offline;
  {
    LogWriter w(path);
    SimRunOptions ro;
    ro.on_frame = [&](const estimator::VioEstimator& est, const FrameSample& s) {
      // What the vins process publishes after a camera update, and a
      // propagation-only state that must be ignored.
      NavState prop = nav_state_of(est, false);
      prop.utime -= 1;
      w.write("VINS_STATE", to_lcm(prop), s.utime - 1);
      w.write("VINS_STATE", to_lcm(nav_state_of(est, true)), s.utime);
      GroundTruth gt;
      gt.utime = s.utime;
      gt.q_GtoI = s.q_GtoI_true;
      gt.p_IinG = s.p_IinG_true;
      w.write("GROUND_TRUTH", to_lcm(gt), s.utime);
    };
    offline = run_vio_on_sim(cfg, o, 3, ro);
  }
  const LogEvalResult logged = evaluate_log(path);
  CHECK(logged.summary.count == offline.errors.count);
  CHECK(logged.summary.rmse_position_m == offline.errors.rmse_position_m);
  CHECK(logged.summary.rmse_orientation_deg == offline.errors.rmse_orientation_deg);
  CHECK(logged.summary.nees_position == offline.errors.nees_position);
  CHECK(logged.summary.nees_orientation == offline.errors.nees_orientation);
  std::remove(path.c_str());
}

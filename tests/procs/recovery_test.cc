// Issue 14, recovery across processes, on the process logic (no LCM): an
// outage of all input (the simulator respawned) is bridged, keeping the
// estimate, clones and landmarks; a respawned vins goes on from its
// checkpoint; a gap or checkpoint too old, and a corrupt checkpoint, are
// refused with a message and the node starts anew; the target filter keeps
// its target across a bridged outage. Scored against the
// simulator's truth: position RMS and the NEES of position and orientation
// of the published states (docs/sheriff.md, "Recovery").
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <unistd.h>
#include <variant>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/checkpoint.h"
#include "common/eval/metrics.h"
#include "procs/target_filter/target_filter_node.h"
#include "procs/vins/vins_node.h"
#include "tests/procs/paper_events.h"

using namespace vimot;

namespace {

constexpr double kDuration = 14.0;        // s of the paper scenario
constexpr int64_t kOutage = 5'000'000;    // µs: the input stops here ...
constexpr int64_t kRespawn = 1'100'000;   // ... for this long (a sheriff's respawn, docs/sheriff.md)
constexpr double kChi2_3dof_99 = 11.345;  // 99 % quantile of χ² with 3 dof

int64_t utime_of(const sim::SimEvent& e) {
  return std::visit([](const auto& x) { return x.utime; }, e);
}

const std::vector<sim::SimEvent>& all_events() {
  static const std::vector<sim::SimEvent> events = simulate(kDuration);
  return events;
}

const std::map<int64_t, GroundTruth>& truth() {
  static const std::map<int64_t, GroundTruth> t = [] {
    std::map<int64_t, GroundTruth> m;
    for (const auto& e : all_events()) {
      if (const auto* gt = std::get_if<GroundTruth>(&e)) m[gt->utime] = *gt;
    }
    return m;
  }();
  return t;
}

// The events with utime in [from, to).
std::vector<sim::SimEvent> events_in(int64_t from, int64_t to) {
  std::vector<sim::SimEvent> out;
  for (const auto& e : all_events()) {
    if (utime_of(e) >= from && utime_of(e) < to) out.push_back(e);
  }
  return out;
}

// Every event but those of an outage of `length` µs at kOutage.
std::vector<sim::SimEvent> with_outage(int64_t length) {
  std::vector<sim::SimEvent> out = events_in(0, kOutage);
  for (const auto& e : events_in(kOutage + length, INT64_MAX)) out.push_back(e);
  return out;
}

VinsNodeOptions vins_options(const std::string& checkpoint = "") {
  VinsNodeOptions o = vins_node_options_from_config(Config::load_file(source_path("config/vins.yaml")));
  o.checkpoint_path = checkpoint;
  return o;
}

struct Run {
  std::vector<NavState> states;  // updated
  std::vector<NodeEvent> events;
  int64_t resets{0};
  int64_t bridged{0};
  bool restored{false};

  bool said(NodeEvent::Kind kind, const std::string& text) const {
    for (const auto& e : events) {
      if (e.kind == kind && e.message.find(text) != std::string::npos) return true;
    }
    return false;
  }
};

Run run_vins(const std::vector<sim::SimEvent>& events, const VinsNodeOptions& options = vins_options()) {
  Run run;
  VinsNode node(
      options, [&](const NavState& s) { if (s.updated) run.states.push_back(s); },
      [&](const NodeEvent& e) { run.events.push_back(e); });
  feed(node, events);
  run.resets = node.resets();
  run.bridged = node.bridged_gaps();
  run.restored = node.restored();
  return run;
}

double rms(const std::vector<NavState>& states, int64_t from = 0, int64_t to = INT64_MAX) {
  double s = 0.0;
  int n = 0;
  for (const NavState& x : states) {
    if (x.utime < from || x.utime >= to) continue;
    s += (x.p_IinG - truth().at(x.utime).p_IinG).squaredNorm();
    ++n;
  }
  return n == 0 ? INFINITY : std::sqrt(s / n);
}

// The first `n` states at or after `from` are consistent: position and
// orientation NEES each below the 99 % χ² bound.
void check_consistent(const std::vector<NavState>& states, int64_t from, int n) {
  int checked = 0;
  for (const NavState& x : states) {
    if (x.utime < from || checked == n) continue;
    const eval::ErrorSample e = eval::error_of(x, truth().at(x.utime));
    INFO("state at utime " << x.utime << ": |dp| " << e.err_p.norm() << " m, 3 sigma_p " << e.sig3_p.transpose()
                           << ", |dtheta| " << e.err_theta.norm() << " rad; NEES p " << e.nees_p << ", theta "
                           << e.nees_theta);
    CHECK(e.nees_p < kChi2_3dof_99);
    CHECK(e.nees_theta < kChi2_3dof_99);
    ++checked;
  }
  CHECK(checked == n);
}

const Run& clean_run() {
  static const Run run = run_vins(all_events());
  return run;
}

struct TempDir {
  std::filesystem::path path;
  TempDir() : path(std::filesystem::temp_directory_path() / ("vimot_recovery_test_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

}  // namespace

TEST_CASE("an outage of all input for 1.1 s is bridged: no reset, said, consistent, accurate", "[recovery]") {
  const Run run = run_vins(with_outage(kRespawn));
  const int64_t back = kOutage + kRespawn;
  CHECK(run.resets == 0);
  CHECK(run.bridged == 1);
  CHECK(run.said(NodeEvent::Kind::kInfo, "bridged"));
  CHECK_FALSE(run.said(NodeEvent::Kind::kError, ""));
  // The first states after the gap, before and after re-locking on the landmarks.
  check_consistent(run.states, back, 10);
  INFO("position RMS over the whole run " << rms(run.states) << " m, undisturbed " << rms(clean_run().states)
                                           << " m; after the gap " << rms(run.states, back) << " m vs "
                                           << rms(clean_run().states, back) << " m");
  CHECK(rms(run.states) <= 1.1 * rms(clean_run().states));
  CHECK(rms(run.states, back) <= 1.1 * rms(clean_run().states, back));
}

TEST_CASE("an outage longer than input.bridge_max_gap_s resets and says so", "[recovery]") {
  const VinsNodeOptions options = vins_options();
  REQUIRE(options.input.bridge_max_gap_s == 3.0);
  const Run run = run_vins(with_outage(3'500'000), options);
  CHECK(run.bridged == 0);
  CHECK(run.resets == 1);
  CHECK(run.said(NodeEvent::Kind::kError, "longer than input.bridge_max_gap_s"));
  CHECK(run.said(NodeEvent::Kind::kInfo, "initialised from ground truth"));
  CHECK(rms(run.states, kOutage + 4'500'000) < 0.1);  // re-initialised and tracking
}

TEST_CASE("a respawned vins goes on from its checkpoint: state reproduced, gap bridged, consistent", "[recovery]") {
  TempDir dir;
  const std::string path = dir.file("vins.ckpt");
  Run before;
  NavState last;
  {
    VinsNode node(
        vins_options(path), [&](const NavState& s) { if (s.updated) before.states.push_back(s); },
        [&](const NodeEvent& e) { before.events.push_back(e); });
    feed(node, events_in(0, kOutage));
    CHECK(before.said(NodeEvent::Kind::kInfo, "no checkpoint"));  // a first start
    REQUIRE_FALSE(before.states.empty());
    last = before.states.back();
  }
  estimator::RobotCheckpoint c;
  std::string why;
  REQUIRE(estimator::read_checkpoint(path, &c, &why));
  CHECK(c.state.utime == last.utime);
  CHECK(c.state.q_GtoI == last.q_GtoI);
  CHECK(c.state.p_IinG == last.p_IinG);
  CHECK(c.state.v_IinG == last.v_IinG);
  CHECK(c.state.bias_gyro == last.bias_gyro);
  CHECK(c.state.bias_accel == last.bias_accel);
  CHECK(c.state.covariance == last.covariance);
  CHECK(c.last_imu.utime <= last.utime);
  CHECK(last.utime - c.last_imu.utime < 10'000);  // the last sample before the state (200 Hz)
  CHECK(static_cast<int>(c.landmarks.size()) == last.num_slam_features);
  CHECK(c.landmarks.size() > 10);
  {
    // Restoring gives back the same state: IMU, landmarks, joint covariance.
    estimator::VioEstimator restored(vins_options().vio);
    estimator::restore(c, &restored);
    const estimator::RobotCheckpoint again = estimator::checkpoint_of(restored);
    CHECK(again.state.p_IinG == c.state.p_IinG);
    CHECK(again.state.q_GtoI == c.state.q_GtoI);
    CHECK(again.covariance == c.covariance);
    REQUIRE(again.landmarks.size() == c.landmarks.size());
    for (std::size_t i = 0; i < c.landmarks.size(); ++i) {
      CHECK(again.landmarks[i].feature_id == c.landmarks[i].feature_id);
      CHECK(again.landmarks[i].p_FinG == c.landmarks[i].p_FinG);
      CHECK(again.landmarks[i].p_FinG_fej == c.landmarks[i].p_FinG_fej);
    }
  }

  const Run after = run_vins(events_in(kOutage + kRespawn, INT64_MAX), vins_options(path));
  CHECK(after.restored);
  CHECK(after.said(NodeEvent::Kind::kInfo, "restored from checkpoint"));
  CHECK_FALSE(after.said(NodeEvent::Kind::kInfo, "initialised from ground truth"));
  CHECK(after.resets == 0);
  CHECK(after.bridged == 1);
  check_consistent(after.states, 0, 10);
  // Re-locked on its landmarks: the first second after the gap as accurate
  // as the undisturbed run there. Later the estimate drifts on its own: a
  // restarted window and tracks are a new realisation of the VIO's drift
  // (reported, docs/sheriff.md "Recovery").
  const int64_t back = kOutage + kRespawn;
  std::vector<NavState> whole = before.states;
  whole.insert(whole.end(), after.states.begin(), after.states.end());
  INFO("position RMS in the second after the gap " << rms(after.states, back, back + 1'000'000) << " m, undisturbed "
                                                   << rms(clean_run().states, back, back + 1'000'000)
                                                   << " m; over the whole run " << rms(whole) << " m, undisturbed "
                                                   << rms(clean_run().states) << " m");
  CHECK(rms(after.states, back, back + 1'000'000) <= 1.1 * rms(clean_run().states, back, back + 1'000'000));
  WARN("restored vins: whole-run position RMS " << rms(whole) << " m, undisturbed " << rms(clean_run().states)
                                                << " m");
}

TEST_CASE("a stale, future, corrupt or missing checkpoint is refused with a message; the node starts anew",
          "[recovery]") {
  TempDir dir;
  const std::string path = dir.file("vins.ckpt");
  run_vins(events_in(0, kOutage), vins_options(path));  // writes the checkpoint at ~kOutage
  std::ifstream in(path, std::ios::binary);
  const std::string good((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  REQUIRE(good.size() > 100);
  auto write = [&](const std::string& bytes) { std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes; };
  auto starts_anew = [&](const Run& run) {
    CHECK_FALSE(run.restored);
    CHECK(run.said(NodeEvent::Kind::kInfo, "initialised from ground truth"));
    CHECK(rms(run.states) < 0.1);
  };

  SECTION("older than input.bridge_max_gap_s") {
    const Run run = run_vins(events_in(kOutage + 4'000'000, INT64_MAX), vins_options(path));
    CHECK(run.said(NodeEvent::Kind::kInfo, "rejected: stale"));
    starts_anew(run);
  }
  SECTION("after the input (another run's)") {
    const Run run = run_vins(events_in(kOutage - 2'000'000, INT64_MAX), vins_options(path));
    CHECK(run.said(NodeEvent::Kind::kInfo, "rejected: stale"));
    starts_anew(run);
  }
  SECTION("a flipped byte") {
    std::string bad = good;
    bad[bad.size() / 2] ^= 0x10;
    write(bad);
    const Run run = run_vins(events_in(kOutage + kRespawn, INT64_MAX), vins_options(path));
    CHECK(run.said(NodeEvent::Kind::kError, "hash mismatch"));
    starts_anew(run);
  }
  SECTION("truncated") {
    write(good.substr(0, good.size() - 9));
    const Run run = run_vins(events_in(kOutage + kRespawn, INT64_MAX), vins_options(path));
    CHECK(run.said(NodeEvent::Kind::kError, "hash mismatch"));
    starts_anew(run);
  }
  SECTION("not a checkpoint") {
    write(std::string(good.size(), 'x'));
    const Run run = run_vins(events_in(kOutage + kRespawn, INT64_MAX), vins_options(path));
    CHECK(run.said(NodeEvent::Kind::kError, "bad magic"));
    starts_anew(run);
  }
  SECTION("missing") {
    std::filesystem::remove(path);
    const Run run = run_vins(events_in(kOutage + kRespawn, INT64_MAX), vins_options(path));
    CHECK(run.said(NodeEvent::Kind::kInfo, "no checkpoint"));
    CHECK_FALSE(run.said(NodeEvent::Kind::kError, ""));
    starts_anew(run);
  }
}

TEST_CASE("bridging needs the estimator's IMU gap noise", "[recovery]") {
  VinsNodeOptions o = vins_options();
  o.vio.propagator.gap_noise = {};
  CHECK_THROWS_WITH(VinsNode(o, nullptr, nullptr), Catch::Contains("imu_gap_noise"));
}

TEST_CASE("a respawned target filter goes on from its robot checkpoint and re-acquires the target", "[recovery]") {
  TempDir dir;
  TargetFilterNodeOptions o =
      node_options_from_config(Config::load_file(source_path("config/target_filter.yaml")));
  o.checkpoint_path = dir.file("target_filter.ckpt");
  std::vector<NavState> before, after;
  std::vector<NodeEvent> said;
  int targets_after = 0;
  {
    TargetFilterNode::Callbacks cb;
    cb.on_nav_state = [&](const NavState& s) { if (s.updated) before.push_back(s); };
    TargetFilterNode node(o, cb);
    feed(node, events_in(0, kOutage));
  }
  TargetFilterNode::Callbacks cb;
  cb.on_nav_state = [&](const NavState& s) { if (s.updated) after.push_back(s); };
  cb.on_target_state = [&](const TargetStateEstimate&) { ++targets_after; };
  cb.on_event = [&](const NodeEvent& e) { said.push_back(e); };
  TargetFilterNode node(o, cb);
  feed(node, events_in(kOutage + kRespawn, INT64_MAX));
  CHECK(node.vins().restored());
  CHECK(node.resets() == 0);
  CHECK(node.target_initialized());
  CHECK(targets_after > 10);
  check_consistent(after, 0, 10);
  std::vector<NavState> whole = before;
  whole.insert(whole.end(), after.begin(), after.end());
  INFO("NAV_STATE position RMS over the whole run " << rms(whole) << " m, before the kill " << rms(before) << " m");
  CHECK(rms(whole) < 0.1);
}

namespace {

// The target filter started from the truth (target.init.mode ground_truth:
// its frame is the true one, so its target is scored directly), run on `events`.
struct TargetRun {
  std::vector<TargetStateEstimate> targets;
  int64_t resets{0};
  int64_t bridged{0};
};

TargetRun run_target_filter(const std::vector<sim::SimEvent>& events) {
  TargetFilterNodeOptions o = node_options_from_config(Config::load_file(source_path("config/target_filter.yaml")));
  o.target.init_mode = target::TargetInitMode::kGroundTruth;
  REQUIRE(o.target.representation == target::TargetRepresentation::kLocal);  // p_TinI's covariance is on the message
  TargetRun run;
  TargetFilterNode::Callbacks cb;
  cb.on_target_state = [&](const TargetStateEstimate& t) { run.targets.push_back(t); };
  TargetFilterNode node(o, cb);
  feed(node, events);
  run.resets = node.resets();
  run.bridged = node.vins().bridged_gaps();
  return run;
}

double target_error(const TargetStateEstimate& t, double* nees) {
  const Eigen::Vector3d e = eval::true_target_in_imu(truth().at(t.utime)).p_TinI - t.p_TinI;
  *nees = eval::nees3(e, t.covariance.block<3, 3>(3, 3));
  return e.norm();
}

double target_rms(const std::vector<TargetStateEstimate>& targets, int64_t from) {
  double s = 0.0, nees = 0.0;
  int n = 0;
  for (const auto& t : targets) {
    if (t.utime < from) continue;
    s += std::pow(target_error(t, &nees), 2);
    ++n;
  }
  return n == 0 ? INFINITY : std::sqrt(s / n);
}

}  // namespace

TEST_CASE("the target is kept across a bridged 1.1 s outage and stays consistent", "[recovery]") {
  const TargetRun clean = run_target_filter(all_events());
  const TargetRun run = run_target_filter(with_outage(kRespawn));
  const int64_t back = kOutage + kRespawn;
  CHECK(run.resets == 0);
  CHECK(run.bridged == 1);
  REQUIRE_FALSE(run.targets.empty());
  REQUIRE(run.targets.front().utime < kOutage);
  // Kept (only a reset drops the target) and published at every frame after the gap (10 Hz).
  int after = 0;
  for (const auto& t : run.targets) after += t.utime >= back ? 1 : 0;
  CHECK(after >= static_cast<int>(10 * (kDuration - 1e-6 * back)) - 1);
  // The first 10 target states after the gap: the target in the IMU frame
  // within its covariance (99 % χ² bound), as the robot's (above).
  int checked = 0;
  for (const auto& t : run.targets) {
    if (t.utime < back || checked == 10) continue;
    double nees = 0.0;
    const double err = target_error(t, &nees);
    INFO("target at utime " << t.utime << ": |dp_TinI| " << err << " m, NEES " << nees);
    CHECK(nees < kChi2_3dof_99);
    ++checked;
  }
  CHECK(checked == 10);
  // Measured, not a bar (docs/sheriff.md "Recovery": the target after a simulator kill).
  WARN("target in IMU after the gap: position RMS " << target_rms(run.targets, back) << " m, undisturbed "
                                                     << target_rms(clean.targets, back) << " m");
}

// Issue 14, recovery across processes, on the process logic (no LCM): an
// outage of all input (the simulator respawned) is bridged, keeping the
// estimate, clones and landmarks; a respawned vins or target filter goes on
// from its checkpoint of the whole state (the target filter bit for bit on
// the same input); a gap or checkpoint too old, and a corrupt or foreign
// checkpoint, are refused with a message and the node starts anew; the
// target filter keeps its target across a bridged outage and a restore. Scored against the
// simulator's truth: position RMS and the NEES of position and orientation
// of the published states (docs/sheriff.md, "Recovery").
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
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

TargetFilterNodeOptions target_filter_options(const std::string& checkpoint = "") {
  TargetFilterNodeOptions o = node_options_from_config(Config::load_file(source_path("config/target_filter.yaml")));
  o.checkpoint_path = checkpoint;
  return o;
}

// True if one of `events` is of `kind` and contains `text`.
bool said_in(const std::vector<NodeEvent>& events, NodeEvent::Kind kind, const std::string& text) {
  for (const auto& e : events) {
    if (e.kind == kind && e.message.find(text) != std::string::npos) return true;
  }
  return false;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

struct Run {
  std::vector<NavState> states;  // updated
  std::vector<NodeEvent> events;
  int64_t resets{0};
  int64_t bridged{0};
  bool restored{false};

  bool said(NodeEvent::Kind kind, const std::string& text) const { return said_in(events, kind, text); }
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
  estimator::EstimatorCheckpoint c;
  std::string why;
  REQUIRE(estimator::read_checkpoint(path, &c, &why));
  CHECK(c.utime == last.utime);
  const estimator::ImuValue imu = c.imu_value();
  CHECK(imu.q_GtoI == last.q_GtoI);
  CHECK(imu.p_IinG == last.p_IinG);
  CHECK(imu.v_IinG == last.v_IinG);
  CHECK(imu.bg == last.bias_gyro);
  CHECK(imu.ba == last.bias_accel);
  REQUIRE(c.variables.front().kind == estimator::kCheckpointImu);
  CHECK(Eigen::MatrixXd(c.covariance.topLeftCorner(15, 15)) == Eigen::MatrixXd(last.covariance));
  CHECK(c.last_imu.utime <= last.utime);
  CHECK(last.utime - c.last_imu.utime < 10'000);  // the last sample before the state (200 Hz)
  int landmarks = 0, clones = 0;
  for (const auto& v : c.variables) {
    landmarks += v.kind == estimator::kCheckpointLandmark ? 1 : 0;
    clones += v.kind == estimator::kCheckpointClone ? 1 : 0;
  }
  CHECK(landmarks == last.num_slam_features);
  CHECK(landmarks > 10);
  CHECK(clones == vins_options().vio.state.max_clones);
  CHECK(c.tracks.size() > 10);
  CHECK_FALSE(c.has_extension);
  {
    // Restoring gives back the same state: every variable, the covariance, the tracks.
    estimator::VioEstimator restored(vins_options().vio);
    REQUIRE(estimator::restore(c, &restored, nullptr, &why));
    const estimator::EstimatorCheckpoint again = estimator::checkpoint_of(restored);
    CHECK(again.utime == c.utime);
    CHECK(again.covariance == c.covariance);
    REQUIRE(again.variables.size() == c.variables.size());
    for (std::size_t i = 0; i < c.variables.size(); ++i) {
      CHECK(again.variables[i].kind == c.variables[i].kind);
      CHECK(again.variables[i].key == c.variables[i].key);
      CHECK(again.variables[i].value == c.variables[i].value);
      CHECK(again.variables[i].fej == c.variables[i].fej);
      CHECK(again.variables[i].anchor_utime == c.variables[i].anchor_utime);
    }
    CHECK(again.tracks.size() == c.tracks.size());
  }

  const Run after = run_vins(events_in(kOutage + kRespawn, INT64_MAX), vins_options(path));
  CHECK(after.restored);
  CHECK(after.said(NodeEvent::Kind::kInfo, "restored from checkpoint"));
  CHECK_FALSE(after.said(NodeEvent::Kind::kInfo, "initialised from ground truth"));
  CHECK(after.resets == 0);
  CHECK(after.bridged == 1);
  check_consistent(after.states, 0, 10);
  // Re-locked on its clones, tracks and landmarks: the first second after
  // the gap as accurate as the undisturbed run there; the whole run is
  // reported (docs/sheriff.md "Recovery").
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
  const std::string good = file_bytes(path);
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

TEST_CASE("a respawned target filter goes on from its checkpoint with its target", "[recovery]") {
  TempDir dir;
  const TargetFilterNodeOptions o = target_filter_options(dir.file("target_filter.ckpt"));
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
  TargetFilterNodeOptions o = target_filter_options();
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

namespace {

// Everything a target filter publishes, with what it said.
struct TargetFilterOutput {
  std::vector<NavState> states;  // updated
  std::vector<TargetStateEstimate> targets;
  std::vector<NodeEvent> events;

  TargetFilterNode::Callbacks callbacks() {
    TargetFilterNode::Callbacks cb;
    cb.on_nav_state = [this](const NavState& s) { if (s.updated) states.push_back(s); };
    cb.on_target_state = [this](const TargetStateEstimate& t) { targets.push_back(t); };
    cb.on_event = [this](const NodeEvent& e) { events.push_back(e); };
    return cb;
  }
  bool said(NodeEvent::Kind kind, const std::string& text) const { return said_in(events, kind, text); }
};

}  // namespace

TEST_CASE("a target filter restored from its checkpoint continues bit for bit", "[recovery]") {
  TempDir dir;
  TargetFilterNodeOptions o = target_filter_options(dir.file("running.ckpt"));
  SECTION("skf, local (config/target_filter.yaml)") {}
  SECTION("adaptive, global") {
    o.target.mode = target::TargetUpdateMode::kAdaptive;
    o.target.representation = target::TargetRepresentation::kGlobal;
  }
  // The uninterrupted filter; its checkpoint as it was when the input reached kOutage.
  TargetFilterOutput whole;
  const std::string at_k = dir.file("at_k.ckpt");
  {
    TargetFilterNode node(o, whole.callbacks());
    for (const auto& e : all_events()) {
      if (utime_of(e) >= kOutage && !std::filesystem::exists(at_k)) {
        std::filesystem::copy_file(o.checkpoint_path, at_k);
      }
      feed_one(node, e);
    }
    node.flush();
  }
  estimator::EstimatorCheckpoint c;
  std::string why;
  REQUIRE(estimator::read_checkpoint(at_k, &c, &why));
  const int64_t k = c.utime;
  int target_vars = 0;
  for (const auto& v : c.variables) target_vars += v.kind >= estimator::kFirstExtensionKind ? 1 : 0;
  INFO("checkpoint at utime " << k << ": " << c.variables.size() << " variables (" << target_vars
                              << " of the target), " << c.tracks.size() << " MSCKF tracks");
  REQUIRE(c.has_extension);
  REQUIRE(target_vars > 5);  // the target, its clones and points

  // Restored on the same input after k (the reading at k comes from the checkpoint).
  TargetFilterNodeOptions restored_options = o;
  restored_options.checkpoint_path = at_k;
  TargetFilterOutput restored;
  TargetFilterNode node(restored_options, restored.callbacks());
  feed(node, events_in(k + 1, INT64_MAX));
  CHECK(node.vins().restored());
  CHECK(restored.said(NodeEvent::Kind::kInfo, "restored from checkpoint"));
  CHECK(node.resets() == 0);

  std::vector<NavState> states;
  std::vector<TargetStateEstimate> targets;
  for (const auto& s : whole.states) if (s.utime > k) states.push_back(s);
  for (const auto& t : whole.targets) if (t.utime > k) targets.push_back(t);
  REQUIRE(states.size() > 100);
  REQUIRE(restored.states.size() == states.size());
  for (std::size_t i = 0; i < states.size(); ++i) {
    INFO("robot state " << i << " at utime " << states[i].utime);
    REQUIRE(restored.states[i].utime == states[i].utime);
    REQUIRE(restored.states[i].q_GtoI == states[i].q_GtoI);
    REQUIRE(restored.states[i].p_IinG == states[i].p_IinG);
    REQUIRE(restored.states[i].v_IinG == states[i].v_IinG);
    REQUIRE(restored.states[i].covariance == states[i].covariance);
  }
  REQUIRE(targets.size() == states.size());
  REQUIRE(restored.targets.size() == targets.size());
  for (std::size_t i = 0; i < targets.size(); ++i) {
    INFO("target state " << i << " at utime " << targets[i].utime);
    REQUIRE(restored.targets[i].utime == targets[i].utime);
    REQUIRE(restored.targets[i].q_ItoT == targets[i].q_ItoT);
    REQUIRE(restored.targets[i].q_GtoT == targets[i].q_GtoT);
    REQUIRE(restored.targets[i].p_TinG == targets[i].p_TinG);
    REQUIRE(restored.targets[i].v_TinT == targets[i].v_TinT);
    REQUIRE(restored.targets[i].w_TinT == targets[i].w_TinT);
    REQUIRE(restored.targets[i].p_TinI == targets[i].p_TinI);
    REQUIRE(restored.targets[i].covariance == targets[i].covariance);
    REQUIRE(restored.targets[i].num_target_points == targets[i].num_target_points);
  }
}

TEST_CASE("a target filter restored after a 1.1 s gap keeps its target, consistent with the truth", "[recovery]") {
  TempDir dir;
  TargetFilterNodeOptions o = target_filter_options(dir.file("target_filter.ckpt"));
  o.target.init_mode = target::TargetInitMode::kGroundTruth;  // the true frame: scored directly
  {
    TargetFilterOutput before;
    TargetFilterNode node(o, before.callbacks());
    feed(node, events_in(0, kOutage));
    REQUIRE(node.target_initialized());
  }
  TargetFilterOutput after;
  TargetFilterNode node(o, after.callbacks());
  const int64_t back = kOutage + kRespawn;
  feed(node, events_in(back, INT64_MAX));
  CHECK(node.vins().restored());
  CHECK(node.resets() == 0);
  CHECK(node.vins().bridged_gaps() == 1);
  // Kept, not re-acquired: a target state at every frame from the first after the gap (10 Hz).
  REQUIRE_FALSE(after.targets.empty());
  CHECK(after.targets.front().utime < back + 150'000);
  CHECK(static_cast<int>(after.targets.size()) >= static_cast<int>(10 * (kDuration - 1e-6 * back)) - 1);
  int checked = 0;
  for (const auto& t : after.targets) {
    if (checked == 10) break;
    double nees = 0.0;
    const double err = target_error(t, &nees);
    INFO("target at utime " << t.utime << ": |dp_TinI| " << err << " m, NEES " << nees);
    CHECK(nees < kChi2_3dof_99);
    ++checked;
  }
  CHECK(checked == 10);
  const TargetRun clean = run_target_filter(all_events());
  WARN("restored target in IMU after the gap: position RMS " << target_rms(after.targets, back) << " m, undisturbed "
                                                              << target_rms(clean.targets, back) << " m");
}

TEST_CASE("a target filter refuses a corrupt, truncated or foreign checkpoint and starts anew", "[recovery]") {
  TempDir dir;
  const std::string path = dir.file("target_filter.ckpt");
  {
    TargetFilterOutput first;
    TargetFilterNode node(target_filter_options(path), first.callbacks());
    feed(node, events_in(0, kOutage));
  }
  const std::string good = file_bytes(path);
  REQUIRE(good.size() > 1000);
  auto write = [&](const std::string& bytes) { std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes; };
  TargetFilterNodeOptions o = target_filter_options(path);
  std::string reason;
  SECTION("truncated") {
    write(good.substr(0, good.size() / 2));
    reason = "hash mismatch";
  }
  SECTION("a flipped byte in the target's part (at the end)") {
    std::string bad = good;
    bad[bad.size() - 20] ^= 0x01;
    write(bad);
    reason = "hash mismatch";
  }
  SECTION("written with another target representation") {
    o.target.representation = target::TargetRepresentation::kGlobal;
    reason = "another configuration";
  }
  SECTION("a vins checkpoint (no target filter part)") {
    run_vins(events_in(0, kOutage), vins_options(path));
    reason = "has no target filter's state";
  }
  TargetFilterOutput after;
  TargetFilterNode node(o, after.callbacks());
  feed(node, events_in(kOutage + kRespawn, INT64_MAX));
  INFO("expected a refusal naming \"" << reason << "\"");
  CHECK(after.said(NodeEvent::Kind::kError, reason));
  CHECK(after.said(NodeEvent::Kind::kError, "starting from ground truth"));
  CHECK_FALSE(node.vins().restored());
  CHECK(node.target_initialized());  // re-acquired from its features
  CHECK(rms(after.states) < 0.1);
}

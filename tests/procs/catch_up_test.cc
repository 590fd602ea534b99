// Issue 14, catch-up from the flight recorder, on the process logic (no
// LCM network): a vins or target filter respawned from its checkpoint with
// the run's LCM log (--catch-up-log) handles the input it missed from the
// log and then goes on with the live input, publishing bit for bit what the
// undisturbed node published after its checkpoint; nothing is handled twice
// or skipped; a log lacking part of the range, truncated or missing falls
// back to bridging the gap and says so.
#include <catch2/catch.hpp>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <variant>
#include <vector>

#include "common/estimator/checkpoint.h"
#include "common/process/catch_up.h"
#include "common/process/event_sink.h"
#include "common/process/lcm_conversions.h"
#include "procs/target_filter/target_filter_node.h"
#include "procs/vins/vins_node.h"
#include "tests/procs/paper_events.h"

using namespace vimot;

namespace {

constexpr double kDuration = 9.0;         // s of the paper scenario
constexpr int64_t kKill = 5'000'000;      // µs: the node dies when the input reaches this ...
constexpr int64_t kRespawn = 1'100'000;   // ... and is back this much later (docs/sheriff.md)
constexpr int64_t kLive = kKill + kRespawn;

int64_t utime_of(const sim::SimEvent& e) {
  return std::visit([](const auto& x) { return x.utime; }, e);
}

const std::vector<sim::SimEvent>& sim_events() {
  static const std::vector<sim::SimEvent> events = simulate(kDuration);
  return events;
}

// Each camera frame after the next 3 IMU samples: FEATURES from a tracker
// arrive after the IMU of their time (the process handles the frame on
// arrival, with IMU samples after it already buffered).
std::vector<sim::SimEvent> frames_late(std::vector<sim::SimEvent> events) {
  for (std::size_t i = events.size(); i-- > 0;) {
    if (!std::holds_alternative<CameraFrame>(events[i])) continue;
    std::size_t j = i;
    int imu_passed = 0;
    while (j + 1 < events.size() && imu_passed < 3 && !std::holds_alternative<CameraFrame>(events[j + 1])) {
      if (std::holds_alternative<ImuData>(events[j + 1])) ++imu_passed;
      std::swap(events[j], events[j + 1]);
      ++j;
    }
  }
  return events;
}

template <typename Msg>
std::vector<uint8_t> bytes_of(const Msg& msg) {
  std::vector<uint8_t> b(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// Every output in publication order, as its LCM bytes (bit for bit).
struct Outputs {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> published;
  std::vector<NodeEvent> events;

  void add(const std::string& channel, std::vector<uint8_t> bytes) { published.emplace_back(channel, std::move(bytes)); }
  bool said(NodeEvent::Kind kind, const std::string& text) const {
    for (const auto& e : events) {
      if (e.kind == kind && e.message.find(text) != std::string::npos) return true;
    }
    return false;
  }
  int count(NodeEvent::Kind kind) const {
    int n = 0;
    for (const auto& e : events) n += e.kind == kind ? 1 : 0;
    return n;
  }
  TargetFilterNode::Callbacks callbacks() {
    TargetFilterNode::Callbacks cb;
    cb.on_nav_state = [this](const NavState& s) { add("NAV_STATE", bytes_of(to_lcm(s))); };
    cb.on_target_state = [this](const TargetStateEstimate& t) { add("TARGET_STATE", bytes_of(to_lcm(t))); };
    cb.on_target_prediction = [this](const TargetPosePrediction& p) { add("TARGET_PREDICTION", bytes_of(to_lcm(p))); };
    cb.on_event = [this](const NodeEvent& e) { events.push_back(e); };
    return cb;
  }
};

// The logger's file: the events in order, except those with utime in [gap_from, gap_to).
void write_log(const std::string& path, const std::vector<sim::SimEvent>& events, int64_t gap_from = INT64_MAX,
               int64_t gap_to = INT64_MAX) {
  LogFileSink sink(path, LogFileSink::Mode::kReplace, /*flush_each=*/true);
  for (const auto& e : events) {
    if (utime_of(e) >= gap_from && utime_of(e) < gap_to) continue;
    if (const auto* imu = std::get_if<ImuData>(&e)) emit(sink, "IMU", to_lcm(*imu));
    if (const auto* frame = std::get_if<CameraFrame>(&e)) emit(sink, "FEATURES", to_lcm(*frame));
    if (const auto* gt = std::get_if<GroundTruth>(&e)) emit(sink, "GROUND_TRUTH", to_lcm(*gt));
  }
}

// The undisturbed node's run: every output, and the checkpoint as it was
// when the input reached kKill (copied to `at_kill`).
template <typename Options, typename MakeNode>
Outputs undisturbed(const std::vector<sim::SimEvent>& events, Options options, const std::string& at_kill,
                    MakeNode make_node) {
  Outputs out;
  auto node = make_node(options, out);
  for (const auto& e : events) {
    if (utime_of(e) >= kKill && !std::filesystem::exists(at_kill)) {
      std::filesystem::copy_file(options.checkpoint_path, at_kill);
    }
    feed_one(*node, e);
  }
  node->flush();
  return out;
}

// The undisturbed outputs after the checkpoint was written: after the
// updated state at the checkpoint's utime on `state_channel`.
std::vector<std::pair<std::string, std::vector<uint8_t>>> after_checkpoint(const Outputs& whole,
                                                                           const std::string& state_channel,
                                                                           int64_t checkpoint_utime) {
  for (std::size_t i = 0; i < whole.published.size(); ++i) {
    if (whole.published[i].first != state_channel) continue;
    nav_state_t s;
    s.decode(whole.published[i].second.data(), 0, static_cast<int>(whole.published[i].second.size()));
    if (s.updated && s.utime == checkpoint_utime) return {whole.published.begin() + i + 1, whole.published.end()};
  }
  return {};
}

// Where the respawned node's live input starts: the first IMU sample at or
// after kLive (what follows it in the stream arrives live too).
std::size_t live_start(const std::vector<sim::SimEvent>& events) {
  std::size_t i = 0;
  while (!(std::holds_alternative<ImuData>(events[i]) && utime_of(events[i]) >= kLive)) ++i;
  return i;
}

std::vector<sim::SimEvent> live_input(const std::vector<sim::SimEvent>& events) {
  return {events.begin() + static_cast<std::ptrdiff_t>(live_start(events)), events.end()};
}

// Messages of type `Input` before the live input with utime after
// `after`: what the catch-up handles.
template <typename Input>
int64_t missed(const std::vector<sim::SimEvent>& events, int64_t after) {
  int64_t n = 0;
  for (std::size_t i = 0; i < live_start(events); ++i) {
    n += std::holds_alternative<Input>(events[i]) && utime_of(events[i]) > after ? 1 : 0;
  }
  return n;
}

VinsNodeOptions vins_options(const std::string& checkpoint) {
  VinsNodeOptions o = vins_node_options_from_config(Config::load_file(source_path("config/vins.yaml")));
  o.checkpoint_path = checkpoint;
  return o;
}

std::unique_ptr<VinsNode> make_vins(const VinsNodeOptions& o, Outputs& out) {
  return std::make_unique<VinsNode>(
      o, [&out](const NavState& s) { out.add("VINS_STATE", bytes_of(to_lcm(s))); },
      [&out](const NodeEvent& e) { out.events.push_back(e); });
}

TargetFilterNodeOptions target_filter_options(const std::string& checkpoint) {
  TargetFilterNodeOptions o = node_options_from_config(Config::load_file(source_path("config/target_filter.yaml")));
  o.checkpoint_path = checkpoint;
  return o;
}

std::unique_ptr<TargetFilterNode> make_target_filter(const TargetFilterNodeOptions& o, Outputs& out) {
  return std::make_unique<TargetFilterNode>(o, out.callbacks());
}

// No input lost, rejected or dropped: nothing skipped, nothing handled twice.
void check_clean_input(const VinsNode& node, const Outputs& out) {
  for (const EstimatorInput input : {EstimatorInput::kImu, EstimatorInput::kFrame, EstimatorInput::kGroundTruth}) {
    INFO(node.guard(input).name());
    CHECK(node.guard(input).lost() == 0);
    CHECK(node.guard(input).rejected() == 0);
  }
  CHECK(out.count(NodeEvent::Kind::kDropped) == 0);
  CHECK(out.count(NodeEvent::Kind::kLost) == 0);
  CHECK(out.count(NodeEvent::Kind::kError) == 0);
  CHECK(node.resets() == 0);
  CHECK(node.bridged_gaps() == 0);
}

}  // namespace

TEST_CASE("a respawned vins caught up from the log publishes bit for bit what the undisturbed one did",
          "[catch_up][recovery]") {
  std::vector<sim::SimEvent> events = sim_events();
  SECTION("frames with the IMU of their time") {}
  SECTION("frames after 3 IMU samples of later times (a tracker's latency)") { events = frames_late(events); }
  TempDir dir;
  const std::string log = dir.file("run.lcmlog");
  write_log(log, events);
  const std::string at_kill = dir.file("at_kill.ckpt");
  const Outputs whole = undisturbed(events, vins_options(dir.file("running.ckpt")), at_kill, make_vins);
  estimator::EstimatorCheckpoint c;
  std::string why;
  REQUIRE(estimator::read_checkpoint(at_kill, &c, &why));
  const auto expected = after_checkpoint(whole, "VINS_STATE", c.utime);
  REQUIRE(expected.size() > 100);

  VinsNodeOptions o = vins_options(at_kill);
  o.catch_up_log = log;
  Outputs restarted;
  const auto node = make_vins(o, restarted);
  std::vector<sim::SimEvent> live = live_input(events);
  std::size_t again = 0;
  SECTION("live input in the log's order") {}
  SECTION("FEATURES and GROUND_TRUTH of the last 30 ms before the first live IMU arrive after it too (another sender)") {
    std::vector<sim::SimEvent> before;
    for (std::size_t i = 0; i < live_start(events); ++i) {
      if (!std::holds_alternative<ImuData>(events[i]) && utime_of(events[i]) >= kLive - 30'000) before.push_back(events[i]);
    }
    again = before.size();
    REQUIRE(again > 3);
    live.insert(live.begin() + 1, before.begin(), before.end());
  }
  for (const auto& e : live) feed_one(*node, e);
  node->flush();

  CHECK(node->restored());
  CHECK(restarted.said(NodeEvent::Kind::kInfo, "restored from checkpoint"));
  CHECK(restarted.said(NodeEvent::Kind::kInfo, "caught up "));
  CHECK(restarted.said(NodeEvent::Kind::kInfo, "GROUND_TRUTH from " + log));
  CHECK_FALSE(restarted.said(NodeEvent::Kind::kInfo, "bridg"));
  check_clean_input(*node, restarted);
  // Exactly the input the undisturbed node handled after its checkpoint, up
  // to the first live message; what arrived again live is not handled again.
  CHECK(node->caught_up(EstimatorInput::kImu) == missed<ImuData>(events, c.utime));
  CHECK(node->caught_up(EstimatorInput::kFrame) == missed<CameraFrame>(events, c.utime));
  CHECK(node->caught_up(EstimatorInput::kGroundTruth) == missed<GroundTruth>(events, c.utime));
  CHECK(node->caught_up(EstimatorInput::kImu) > 200);
  CHECK(node->already_handled() == static_cast<int64_t>(again));

  REQUIRE(restarted.published.size() == expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    INFO("output " << i << " of " << expected.size());
    REQUIRE(restarted.published[i] == expected[i]);
  }
}

TEST_CASE("a respawned target filter caught up from the log: NAV_STATE and TARGET_STATE bit for bit",
          "[catch_up][recovery]") {
  std::vector<sim::SimEvent> events = sim_events();
  SECTION("frames with the IMU of their time") {}
  SECTION("frames after 3 IMU samples of later times") { events = frames_late(events); }
  TempDir dir;
  const std::string log = dir.file("run.lcmlog");
  write_log(log, events);
  const std::string at_kill = dir.file("at_kill.ckpt");
  const Outputs whole = undisturbed(events, target_filter_options(dir.file("running.ckpt")), at_kill,
                                                      make_target_filter);
  estimator::EstimatorCheckpoint c;
  std::string why;
  REQUIRE(estimator::read_checkpoint(at_kill, &c, &why));
  REQUIRE(c.has_extension);
  // The target outputs of the checkpoint's frame follow its checkpoint: the dead process published them.
  auto expected = after_checkpoint(whole, "NAV_STATE", c.utime);
  while (!expected.empty() && expected.front().first != "NAV_STATE") expected.erase(expected.begin());
  int targets = 0;
  for (const auto& [channel, b] : expected) targets += channel == "TARGET_STATE" ? 1 : 0;
  REQUIRE(targets > 20);

  TargetFilterNodeOptions o = target_filter_options(at_kill);
  o.catch_up_log = log;
  Outputs restarted;
  const auto node = make_target_filter(o, restarted);
  for (const auto& e : live_input(events)) feed_one(*node, e);
  node->flush();

  CHECK(node->vins().restored());
  CHECK(node->target_initialized());
  CHECK(restarted.said(NodeEvent::Kind::kInfo, "caught up "));
  check_clean_input(node->vins(), restarted);
  CHECK(node->vins().already_handled() == 0);
  CHECK(node->vins().caught_up(EstimatorInput::kFrame) == missed<CameraFrame>(events, c.utime));
  CHECK(node->vins().caught_up(EstimatorInput::kGroundTruth) == missed<GroundTruth>(events, c.utime));
  REQUIRE(restarted.published.size() == expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    INFO("output " << i << " of " << expected.size() << " on " << expected[i].first);
    REQUIRE(restarted.published[i] == expected[i]);
  }
}

TEST_CASE("a catch-up log lacking part of the range, truncated or missing: bridged and said, no crash",
          "[catch_up][recovery]") {
  const std::vector<sim::SimEvent>& events = sim_events();
  TempDir dir;
  const std::string at_kill = dir.file("at_kill.ckpt");
  undisturbed(events, vins_options(dir.file("running.ckpt")), at_kill, make_vins);
  const std::string log = dir.file("run.lcmlog");
  std::string expect;
  SECTION("the logger down for 0.6 s of the range") {
    write_log(log, events, kKill + 200'000, kKill + 800'000);
    expect = "s of IMU before utime";
  }
  SECTION("the log ends inside the range (the logger died)") {
    write_log(log, events, kKill + 500'000);
    expect = "s before the live input at utime";
  }
  SECTION("truncated in the middle of an event") {
    write_log(log, events, kKill + 500'000);
    std::filesystem::resize_file(log, std::filesystem::file_size(log) - 7);
    expect = "s before the live input at utime";
  }
  SECTION("missing") { expect = "no catch-up: cannot open LCM log '" + log + "'; bridging the gap"; }
  VinsNodeOptions o = vins_options(at_kill);
  o.catch_up_log = log;
  Outputs restarted;
  const auto node = make_vins(o, restarted);
  for (const auto& e : live_input(events)) feed_one(*node, e);
  node->flush();
  INFO("expected to say: " << expect);
  CHECK(restarted.said(NodeEvent::Kind::kInfo, expect));
  CHECK(node->restored());
  CHECK(node->resets() == 0);
  CHECK(node->bridged_gaps() == 1);
  CHECK(node->frames_processed() > 20);
}

TEST_CASE("CatchUpLog: input messages in log order from a utime, malformed ones counted", "[catch_up]") {
  TempDir dir;
  const std::string path = dir.file("run.lcmlog");
  {
    LogFileSink sink(path);
    ImuData imu;
    imu.w_IinI.setZero();
    imu.a_IinI.setZero();
    for (int64_t t : {100, 200, 300}) {
      imu.utime = t;
      emit(sink, "IMU", to_lcm(imu));
      GroundTruth gt{};
      gt.utime = t;
      emit(sink, "GROUND_TRUTH", to_lcm(gt));
    }
    const char junk[] = "not an imu_t";
    sink.write("IMU", 350, junk, sizeof junk);
    emit(sink, "OTHER", to_lcm(imu));
    CameraFrame frame;
    frame.utime = 250;
    emit(sink, "FEATURES", to_lcm(frame));
  }
  CatchUpChannels channels;
  channels.ground_truth = "";  // not read
  CatchUpLog log(path, channels, 200);
  std::vector<std::pair<EstimatorInput, int64_t>> read;
  LoggedInput m;
  while (log.next(&m)) read.emplace_back(m.input, m.utime);
  const std::vector<std::pair<EstimatorInput, int64_t>> expected = {
      {EstimatorInput::kImu, 200}, {EstimatorInput::kImu, 300}, {EstimatorInput::kFrame, 250}};
  CHECK(read == expected);
  CHECK(log.malformed() == 1);
  CHECK(log.first_malformed().find("on IMU") != std::string::npos);
  CHECK_THROWS_WITH(CatchUpLog(dir.file("none.lcmlog"), channels, 0), Catch::Contains("cannot open LCM log"));
}

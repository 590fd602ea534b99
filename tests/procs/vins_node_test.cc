// The vins process logic without LCM: the published states do not depend on
// how IMU and camera messages interleave on the network, bad input is
// dropped and reported without changing the estimate, and the estimate is
// accurate against simulator truth.
#include <catch2/catch.hpp>

#include <cmath>
#include <utility>
#include <variant>

#include "common/config/config.h"
#include "common/estimator/vins_config.h"
#include "common/eval/sim_runner.h"
#include "common/sim/simulator.h"
#include "procs/vins/vins_node.h"
#include "tests/procs/paper_events.h"
#include "procs/eval/vio_run.h"

using namespace vimot;

namespace {

struct Outputs {
  std::vector<NavState> updated;
  std::vector<NavState> propagated;
  std::vector<NodeEvent> events;
};

Outputs run_node(const std::vector<sim::SimEvent>& events, int imu_rate_every = 1) {
  VinsNodeOptions options;
  options.vio = estimator::load_vio_options(source_path("config/vins.yaml"));
  options.imu_rate_every = imu_rate_every;
  Outputs out;
  VinsNode node(
      options,
      [&](const NavState& s) { (s.updated ? out.updated : out.propagated).push_back(s); },
      [&](const NodeEvent& e) { out.events.push_back(e); });
  for (const auto& e : events) {
    if (const auto* imu = std::get_if<ImuData>(&e)) node.on_imu(*imu);
    if (const auto* frame = std::get_if<CameraFrame>(&e)) node.on_frame(*frame);
    if (const auto* gt = std::get_if<GroundTruth>(&e)) node.on_ground_truth(*gt);
  }
  node.flush();
  return out;
}

bool same_states(const std::vector<NavState>& a, const std::vector<NavState>& b) {
  if (a.size() != b.size()) {
    WARN("different number of states: " << a.size() << " vs " << b.size());
    return false;
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].utime != b[i].utime || a[i].p_IinG != b[i].p_IinG || a[i].q_GtoI != b[i].q_GtoI ||
        a[i].covariance != b[i].covariance) {
      WARN("first difference at state " << i << ", utime " << a[i].utime << " vs " << b[i].utime << ", |dp| "
                                        << (a[i].p_IinG - b[i].p_IinG).norm());
      return false;
    }
  }
  return true;
}

}  // namespace

TEST_CASE("vins node output does not depend on message interleaving", "[vins]") {
  const std::vector<sim::SimEvent> events = simulate(8.0);
  const Outputs in_order = run_node(events);
  REQUIRE(in_order.updated.size() >= 75);

  // Every camera frame delivered before the last 5 IMU samples up to its
  // time (it arrives early on the network): it must wait for them.
  // (The first frame stays after the ground truth that initialises the
  // filter: a frame before initialisation is rightly dropped.)
  const Outputs reordered = run_node(frames_early(events));
  CHECK(same_states(in_order.updated, reordered.updated));
}

TEST_CASE("vins node publishes exactly the offline evaluator's states", "[vins]") {
  // The evaluator (eval::run_vio_on_sim) samples exactly the states the node
  // publishes on the simulator's messages fed directly (its own feeding goes
  // through the LCM structs, procs/eval/sim_pipeline.h).
  sim::SimConfig cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  cfg.seed = 5;
  cfg.duration = 8.0;
  cfg.ground_truth_events = true;
  VinsNodeOptions options;
  options.vio = estimator::load_vio_options(source_path("config/vins.yaml"));
  options.perturb_seed = 9;
  options.publish_imu_rate = false;
  const eval::SimRunResult offline = eval::run_vio_on_sim(cfg, options.vio, options.perturb_seed);
  REQUIRE(offline.samples.size() >= 75);

  std::vector<NavState> updated;
  VinsNode node(options, [&](const NavState& s) { updated.push_back(s); }, {});
  sim::Simulator(cfg).run([&](const sim::SimEvent& e) {
    if (const auto* imu = std::get_if<ImuData>(&e)) node.on_imu(*imu);
    if (const auto* frame = std::get_if<CameraFrame>(&e)) node.on_frame(*frame);
    if (const auto* gt = std::get_if<GroundTruth>(&e)) node.on_ground_truth(*gt);
  });
  node.flush();
  REQUIRE(updated.size() == offline.samples.size());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < updated.size(); ++i) {
    const eval::FrameSample& o = offline.samples[i];
    const NavState& n = updated[i];
    differing += n.utime != o.utime || n.q_GtoI != o.q_GtoI || n.p_IinG != o.p_IinG || n.v_IinG != o.v_IinG ||
                 n.covariance.diagonal() != o.cov_diag;
  }
  CHECK(differing == 0);
}

TEST_CASE("vins node drops duplicate, out-of-order and non-finite input without effect", "[vins]") {
  const std::vector<sim::SimEvent> events = simulate(5.0);
  const Outputs clean = run_node(events);

  std::vector<sim::SimEvent> dirty;
  int frames = 0;
  for (const auto& e : events) {
    dirty.push_back(e);
    if (const auto* frame = std::get_if<CameraFrame>(&e)) {
      if (++frames == 10) dirty.push_back(*frame);  // duplicate frame
    }
    if (const auto* imu = std::get_if<ImuData>(&e)) {
      if (imu->utime % 100000 == 35000) {
        ImuData stale = *imu;
        stale.utime -= 20000;  // out of order
        dirty.push_back(stale);
        ImuData nan = *imu;
        nan.utime += 1;
        nan.a_IinI.x() = std::nan("");
        dirty.push_back(nan);
      }
    }
  }
  const Outputs out = run_node(dirty);
  CHECK(same_states(clean.updated, out.updated));
  int dropped = 0;
  for (const auto& e : out.events) dropped += e.kind == NodeEvent::Kind::kDropped;
  int clean_dropped = 0;
  for (const auto& e : clean.events) clean_dropped += e.kind == NodeEvent::Kind::kDropped;
  CHECK(dropped > clean_dropped);
}

TEST_CASE("vins node publishes IMU-rate predictions between updates and tracks the truth", "[vins]") {
  const std::vector<sim::SimEvent> events = simulate(10.0);
  const Outputs out = run_node(events);
  REQUIRE(!out.updated.empty());
  // 20 IMU samples per frame at 200 Hz / 10 Hz: one prediction for each
  // sample not at a frame time.
  CHECK(out.propagated.size() >= 18 * (out.updated.size() - 1));
  for (std::size_t i = 1; i < out.propagated.size(); ++i) {
    REQUIRE(out.propagated[i].utime > out.propagated[i - 1].utime);
  }
  std::map<int64_t, GroundTruth> truth;
  for (const auto& e : events) {
    if (const auto* gt = std::get_if<GroundTruth>(&e)) truth[gt->utime] = *gt;
  }
  double worst = 0.0;
  for (const auto& s : out.updated) worst = std::max(worst, (s.p_IinG - truth.at(s.utime).p_IinG).norm());
  for (const auto& s : out.propagated) {
    worst = std::max(worst, (s.p_IinG - truth.at(s.utime).p_IinG).norm());
    // The published covariance stays a covariance.
    REQUIRE(s.covariance.diagonal().minCoeff() > 0.0);
  }
  // 10 s, 15 m of flight from a perturbed truth: centimetres, not metres.
  CHECK(worst < 0.1);
}

TEST_CASE("vins node thins the IMU-rate output without changing it", "[vins]") {
  const std::vector<sim::SimEvent> events = simulate(5.0);
  const Outputs full = run_node(events);
  const Outputs thin = run_node(events, 10);
  CHECK(same_states(full.updated, thin.updated));
  REQUIRE(full.propagated.size() > 100);
  REQUIRE(thin.propagated.size() == (full.propagated.size() + 9) / 10);
  std::vector<NavState> every_tenth;
  for (std::size_t i = 0; i < full.propagated.size(); i += 10) every_tenth.push_back(full.propagated[i]);
  CHECK(same_states(every_tenth, thin.propagated));
}

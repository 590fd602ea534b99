// Offline equals LCM, end to end: the simulator's messages written to an LCM
// log as `vimot-sim --log` writes them, replayed through the process Nodes
// by vimot-log-replay (replay_log, its output log) and evaluated by
// vimot-log-eval (evaluate_log), give exactly the figures vimot-vio-eval
// and vimot-target-eval (run_vio_on_sim, run_target_on_sim) report for the
// same seeds and configs.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <string>

#include "common/config/config.h"
#include "common/eval/log_eval.h"
#include "common/process/event_sink.h"
#include "common/process/lcm_conversions.h"
#include "common/sim/simulator.h"
#include "procs/eval/target_run.h"
#include "procs/eval/vio_run.h"
#include "procs/log_replay/log_replay.h"
#include "procs/target_filter/target_filter_node.h"

using namespace vimot;

namespace {

const std::string kSource = VIMOT_SOURCE_DIR;
constexpr uint64_t kPerturbSeed = 7;

std::string temp_log(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("eval_replay_test_" + std::to_string(::getpid()) + "_" + name);
}

sim::SimConfig scenario() {
  sim::SimConfig cfg = sim::from_config(Config::load_file(kSource + "/config/sim_paper.yaml"));
  cfg.seed = 4;
  cfg.duration = 6.0;
  cfg.ground_truth_events = true;
  return cfg;
}

/// The simulator's inputs as vimot-sim --log writes them (drivers/sim/main.cc).
void write_sim_log(const std::string& path) {
  sim::Simulator sim(scenario());
  LogFileSink log(path);
  while (const auto event = sim.next()) {
    if (const auto* imu = std::get_if<ImuData>(&*event)) emit(log, "IMU", to_lcm(*imu));
    if (const auto* frame = std::get_if<CameraFrame>(&*event)) emit(log, "FEATURES", to_lcm(*frame));
    if (const auto* truth = std::get_if<GroundTruth>(&*event)) emit(log, "GROUND_TRUTH", to_lcm(*truth));
  }
}

/// The log replayed through the Nodes of `setup`'s configs, the outputs evaluated as a live run's.
eval::LogEvalResult replay_and_evaluate(ReplaySetup setup, const eval::LogEvalOptions& options) {
  const std::string input = temp_log("input");
  const std::string output = temp_log("output");
  write_sim_log(input);
  setup.perturb_seed = static_cast<int64_t>(kPerturbSeed);
  setup.out_log = output;
  const ReplayReport report = replay_log(input, setup);
  CHECK(report.malformed == 0);
  CHECK(report.node_errors == 0);
  eval::LogEvalResult r = eval::evaluate_log(output, options);
  std::filesystem::remove(input);
  std::filesystem::remove(output);
  return r;
}

}  // namespace

TEST_CASE("vimot-vio-eval's figures are those of its seed replayed through the vins Node and logged",
          "[eval][replay]") {
  const Config vins = Config::load_file(kSource + "/config/vins.yaml");
  const VinsNodeOptions o = vins_node_options_from_config(vins);
  const eval::SimRunResult offline = eval::run_vio_on_sim(scenario(), o.vio, kPerturbSeed, {}, o.input);
  REQUIRE_FALSE(offline.diverged);
  REQUIRE(offline.errors.count >= 50);

  ReplaySetup setup;
  setup.vins_config = kSource + "/config/vins.yaml";
  const eval::LogEvalResult logged = replay_and_evaluate(setup, {});
  CHECK(logged.summary.count == offline.errors.count);
  CHECK(logged.summary.rmse_position_m == offline.errors.rmse_position_m);
  CHECK(logged.summary.rmse_orientation_deg == offline.errors.rmse_orientation_deg);
  CHECK(logged.summary.nees_position == offline.errors.nees_position);
  CHECK(logged.summary.nees_orientation == offline.errors.nees_orientation);
}

TEST_CASE("vimot-target-eval's figures are those of its seed replayed through the target_filter Node and logged",
          "[eval][replay]") {
  const TargetFilterNodeOptions o =
      node_options_from_config(Config::load_file(kSource + "/config/target_filter.yaml"));
  REQUIRE(o.target.init_mode == target::TargetInitMode::kFeatures);
  const eval::TargetRunResult offline = eval::run_target_on_sim(scenario(), o.vio, o.target, kPerturbSeed, {}, false,
                                                                std::nullopt, std::nullopt, o.input);
  REQUIRE_FALSE(offline.diverged);
  REQUIRE(offline.target_in_imu.count >= 40);

  ReplaySetup setup;
  setup.target_filter_config = kSource + "/config/target_filter.yaml";
  eval::LogEvalOptions options;
  options.state_channel = "NAV_STATE";
  options.target_channel = "TARGET_STATE";
  options.target_own_frame = true;  // started from its features: compared through the fixed transform
  const eval::LogEvalResult logged = replay_and_evaluate(setup, options);
  // Position and orientation errors (the NEES of the frame the filter does
  // not estimate in needs the joint covariance, which is not published).
  for (const auto& [live, off] : {std::pair{logged.target_in_imu, offline.target_in_imu},
                                  std::pair{logged.target_in_world, offline.target_in_world}}) {
    CHECK(live.count == off.count);
    CHECK(live.rmse_position_m == off.rmse_position_m);
    CHECK(live.rmse_orientation_deg == off.rmse_orientation_deg);
  }
}

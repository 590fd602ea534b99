// Consistency of the target filter (issue 15 item 3): with the shipped
// configs (config/target_filter.yaml: target started from its own features,
// observability constraint on) the mean target-in-IMU NEES of a few runs
// stays in the band [1.5, 6] (3 is ideal for 3 dof; below the band the
// filter claims too little, above it too much), position and orientation,
// local and global SKF, at the small and the large end of the σ_t range the
// band is asked for; so does the target's orientation in the world. The
// target's position in the world is the robot's position plus the target in
// the IMU: its NEES follows the robot's (VIO's) own, which reads low on
// these short runs (≈ 1.9), so it is reported, not checked. The target is the
// paper's constant-speed semicircle, so every σ_t there is a right model.
// The filter before issue 15 (no observability constraint, gauge prior
// 0.01) fails it: run with env TARGET_CONFIG=<a copy of the config with
// those settings> (docs/evaluation.md, "Target NEES band").
#include <catch2/catch.hpp>

#include <cstdlib>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/vins_config.h"
#include "common/eval/target_eval.h"
#include "common/sim/sim_config.h"
#include "procs/eval/target_run.h"

using namespace vimot;
using namespace vimot::eval;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

constexpr double kDuration = 40.0;  // [s] of the semicircle
constexpr int kRuns = 3;

std::vector<TargetCell> sweep(const target::TargetFilterOptions& filter) {
  sim::SimConfig sim_cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  sim_cfg.duration = kDuration;
  const estimator::VioOptions vo = estimator::load_vio_options(source_path("config/vins.yaml"));
  TargetSweepOptions o;
  o.sigmas = {0.01, 0.1};
  o.modes = {target::TargetUpdateMode::kSkf};
  o.representations = {target::TargetRepresentation::kLocal, target::TargetRepresentation::kGlobal};
  o.vio_only = false;
  o.runs = kRuns;
  o.threads = 1;
  return run_target_sweep(sim_cfg, vo, filter, o);
}

bool in_band(double nees) { return nees >= 1.5 && nees <= 6.0; }

// Every NEES of every cell in the band.
bool all_in_band(const std::vector<TargetCell>& cells) {
  bool ok = true;
  for (const TargetCell& c : cells) {
    const TargetCellSummary s = summarize(c);
    INFO(target::to_string(c.filter.representation) << " σ_t " << c.filter.sigma_t << ": T in I NEES "
                                                    << s.target_in_imu.nees_position.mean << " / "
                                                    << s.target_in_imu.nees_orientation.mean << ", T in G NEES "
                                                    << s.target_in_world.nees_position.mean << " / "
                                                    << s.target_in_world.nees_orientation.mean);
    CHECK(s.diverged == 0);
    CHECK(s.runs == kRuns);
    const bool cell_ok = in_band(s.target_in_imu.nees_position.mean) &&
                         in_band(s.target_in_imu.nees_orientation.mean) &&
                         in_band(s.target_in_world.nees_orientation.mean);
    CHECK(cell_ok);  // reported per cell (INFO above) before the overall verdict
    ok = ok && cell_ok;
  }
  return ok;
}

}  // namespace

TEST_CASE("target NEES in [1.5, 6] with the shipped config, local and global SKF, σ_t 0.01 and 0.1",
          "[target_filter][consistency]") {
  const char* other = std::getenv("TARGET_CONFIG");
  const target::TargetFilterOptions filter =
      target_filter_options(Config::load_file(other ? std::string(other) : source_path("config/target_filter.yaml")));
  CHECK(all_in_band(sweep(filter)));
}

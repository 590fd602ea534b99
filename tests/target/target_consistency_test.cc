// Consistency of the target filter (issue 15 item 3): with the shipped
// configs (config/target_filter.yaml: target started from its own features,
// observability constraint off) the mean target NEES of three whole runs of
// the semicircle (104.7 s) stays in the band [1.5, 6] (3 is ideal for 3 dof;
// below the band the filter claims too little, above it too much): position
// and orientation of the target in the IMU and in the world, local and
// global SKF, at the small and the large end of the σ_t range the band is
// asked for. The target is the paper's constant-speed semicircle, so every
// σ_t there is a right model. Whole runs because the over-confidence of the
// observability-constrained filter (the target's roll about its heading)
// grows with the run's length and passes 40-s runs: run with env
// TARGET_CONFIG=<a copy of the config with observability_constraint: true>
// to see it fail (docs/evaluation.md, "Target NEES band").
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

constexpr int kRuns = 3;

std::vector<TargetCell> sweep(const target::TargetFilterOptions& filter) {
  sim::SimConfig sim_cfg = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
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
                         in_band(s.target_in_world.nees_position.mean) &&
                         in_band(s.target_in_world.nees_orientation.mean);
    CHECK(cell_ok);  // reported per cell (INFO above) before the overall verdict
    ok = ok && cell_ok;
  }
  return ok;
}

}  // namespace

TEST_CASE("whole-run target NEES in [1.5, 6] with the shipped config, local and global SKF, σ_t 0.01 and 0.1",
          "[target_filter][consistency]") {
  const char* other = std::getenv("TARGET_CONFIG");
  const target::TargetFilterOptions filter =
      target_filter_options(Config::load_file(other ? std::string(other) : source_path("config/target_filter.yaml")));
  CHECK(all_in_band(sweep(filter)));
}

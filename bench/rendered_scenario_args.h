// Options of the benches that track a rendered scenario (--sim, --tracker,
// --seed, --duration) and what they load.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "common/config/config.h"
#include "common/frontend/tracker_options.h"
#include "common/process/arg_parser.h"
#include "common/sim/sim_config.h"

namespace vimot {

inline void add_rendered_scenario_options(ArgParser& args, const char* sim_default, const char* tracker_default,
                                          const char* duration_default) {
  args.add_option("sim", "FILE", "simulator config", sim_default);
  args.add_option("tracker", "FILE", "feature tracker config (its tracker: section)", tracker_default);
  args.add_option("seed", "N", "simulator seed", "1");
  args.add_option("duration", "S", "seconds simulated", duration_default);
}

struct RenderedScenario {
  sim::SimConfig sim;
  frontend::FeatureTrackerOptions tracker;
};

/// The scenario of --sim with --seed and --duration, the tracker of
/// --tracker; OpenCV on one thread (the benches time one core).
inline RenderedScenario rendered_scenario_from(const ArgParser& args) {
  cv::setNumThreads(1);
  RenderedScenario r;
  r.sim = sim::from_config(Config::load_file(args.get("sim")));
  r.sim.seed = static_cast<uint64_t>(args.get_int("seed"));
  r.sim.duration = args.get_double("duration");
  r.tracker = frontend::FeatureTrackerOptions::from_config(Config::load_file(args.get("tracker")), "tracker");
  return r;
}

}  // namespace vimot

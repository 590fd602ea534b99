#pragma once
// The command-line options every Monte-Carlo evaluation tool shares
// (vimot-vio-eval, vimot-target-eval, vimot-scale-eval): --runs,
// --first-seed, --threads, --duration, --perturb-seed, --pixels, declared
// and checked in one place.

#include <cstdint>
#include <optional>
#include <string>

#include "common/frontend/tracker_options.h"
#include "common/segmentation/box_chain.h"
#include "common/process/arg_parser.h"

namespace vimot {
namespace eval {

/// Declares the options; `runs_help` and `default_runs` differ per tool.
void add_monte_carlo_args(ArgParser& args, const std::string& runs_help, const std::string& default_runs);

struct MonteCarloArgs {
  int runs{1};
  uint64_t first_seed{1};
  int threads{1};                        // --threads 0 resolved to the hardware concurrency
  std::optional<double> duration_s;      // --duration
  std::optional<uint64_t> perturb_seed;  // --perturb-seed (0 = start at the truth)
  /// --pixels FILE: frames from rendered images through the feature tracker,
  /// its options from FILE's `tracker:` section (the feature_tracker process's config).
  std::optional<frontend::FeatureTrackerOptions> pixels;
  /// --segmenter FILE --mask-filter FILE (with --pixels): the target box
  /// from the segmenter and the mask filter instead of the truth.
  std::optional<segmentation::BoxChainOptions> box_chain;
};

/// Reads and checks them after ArgParser::parse. Throws ArgError naming the
/// option on a bad value.
MonteCarloArgs read_monte_carlo_args(const ArgParser& args);

}  // namespace eval
}  // namespace vimot

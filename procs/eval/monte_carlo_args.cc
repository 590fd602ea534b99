#include "procs/eval/monte_carlo_args.h"

#include <algorithm>
#include <thread>

#include "common/config/config.h"

namespace vimot {
namespace eval {

void add_monte_carlo_args(ArgParser& args, const std::string& runs_help, const std::string& default_runs) {
  args.add_option("runs", "N", runs_help, default_runs);
  args.add_option("first-seed", "S", "simulator seed of the first run", "1");
  args.add_option("threads", "K", "parallel runs (0 = hardware concurrency)", "0");
  args.add_option("duration", "SECONDS", "simulate only this long (default: the config's)");
  args.add_option("perturb-seed", "P",
                  "perturbation seed of the start for every run instead of one derived from the\n"
                  "simulator seed (e.g. the vins config's init.perturb_seed, to reproduce an LCM\n"
                  "run); 0 = start at the truth");
  args.add_option("pixels", "FILE",
                  "frames from pixels: the rendered images through the feature tracker, configured\n"
                  "by FILE's tracker: section (e.g. config/feature_tracker_sim.yaml), target box = truth");
  args.add_option("segmenter", "FILE",
                  "with --pixels: the target box from the segmenter configured by FILE\n"
                  "(config/segmenter.yaml) and the mask filter of --mask-filter, not the truth");
  args.add_option("mask-filter", "FILE", "with --segmenter: the mask filter's config (config/mask_filter.yaml)");
}

MonteCarloArgs read_monte_carlo_args(const ArgParser& args) {
  MonteCarloArgs a;
  const long long runs = args.get_int("runs");
  const long long first = args.get_int("first-seed");
  const long long threads = args.get_int("threads");
  if (runs < 1) throw ArgError("--runs must be >= 1, got " + args.get("runs"));
  if (first < 0) throw ArgError("--first-seed must be >= 0, got " + args.get("first-seed"));
  if (threads < 0) throw ArgError("--threads must be >= 0, got " + args.get("threads"));
  a.runs = static_cast<int>(runs);
  a.first_seed = static_cast<uint64_t>(first);
  a.threads = threads > 0 ? static_cast<int>(threads) : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  if (args.given("duration")) a.duration_s = args.get_double("duration");
  if (args.given("perturb-seed")) {
    const long long p = args.get_int("perturb-seed");
    if (p < 0) throw ArgError("--perturb-seed must be >= 0, got " + args.get("perturb-seed"));
    a.perturb_seed = static_cast<uint64_t>(p);
  }
  if (args.given("pixels")) {
    a.pixels = frontend::FeatureTrackerOptions::from_config(Config::load_file(args.get("pixels")), "tracker");
  }
  if (args.given("segmenter") != args.given("mask-filter")) throw ArgError("--segmenter and --mask-filter go together");
  if (args.given("segmenter")) {
    if (!a.pixels) throw ArgError("--segmenter needs --pixels (it segments the rendered images)");
    a.box_chain = segmentation::BoxChainOptions::from_config_files(args.get("segmenter"), args.get("mask-filter"));
  }
  return a;
}

}  // namespace eval
}  // namespace vimot

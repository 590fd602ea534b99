// The monocular metric scale from rendered pixels (issue 11; vimot-scale-eval
// --pixels): the shipped mono scenario (config/sim_mono.yaml, 60 s, seed 1)
// rendered and tracked by the feature tracker (config/feature_tracker_sim_mono.yaml,
// true box), then mono VIO, the object tracker and the scale estimator as
// shipped. The truth of the track's scale comes from the renderer's ray cast
// of its reference features (eval::object_truth_from_pixels), not from the
// simulator's feature ids. The bound is the issue's: an accepted scale
// within 3 % of the truth (here every accepted estimate's median, and the
// one held at the end).
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/eval/evaluation_setup.h"
#include "common/frontend/tracker_options.h"
#include "procs/eval/scale_run.h"

using namespace vimot;

namespace {

const std::string kSource = VIMOT_SOURCE_DIR;

}  // namespace

TEST_CASE("metric scale from rendered pixels: accepted and within 3 % of the truth", "[eval][scale][pixels]") {
  const eval::EvaluationSetup setup = eval::load_evaluation_setup(
      kSource + "/config/sim_mono.yaml", kSource + "/config/vins_mono.yaml", std::nullopt);
  eval::ScaleEvalOptions options;
  options.vio = setup.vio;
  options.tracker = object_tracker_options_from_config(Config::load_file(kSource + "/config/object_tracker.yaml"));
  options.node = scale_node_options_from_config(Config::load_file(kSource + "/config/scale_estimator.yaml"));
  options.pixels = frontend::FeatureTrackerOptions::from_config(
      Config::load_file(kSource + "/config/feature_tracker_sim_mono.yaml"), "tracker");

  const eval::ScaleRunResult r =
      eval::run_scale_on_sim(setup.sim, options, estimator::perturb_seed_for_run(setup.sim.seed));
  const eval::AbsStats errors = eval::abs_stats(r.figures.accepted_scale_errors);
  INFO(r.tracks.size() << " object tracks, " << r.tracker_valid_frames << " of " << r.frames << " frames valid, "
                       << r.figures.estimates << " scale estimates, " << r.figures.accepted << " accepted; |error| median "
                       << errors.median << ", max " << errors.max << ", held at the end "
                       << r.figures.final_scale_error);
  REQUIRE_FALSE(r.vio_diverged);
  REQUIRE(r.figures.accepted > 0);
  CHECK(errors.median <= 0.03);
  CHECK(std::abs(r.figures.final_scale_error) <= 0.03);
}

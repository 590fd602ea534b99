// vimot-bench-tracker-accuracy: the feature tracker's pixel error on the
// rendered simulator's images against the renderer's exact geometry
// (common/eval/tracker_accuracy.h): every observation after a track's first
// against the projection of the point its first observation's ray hit.
// Broken down by camera, track age, distance to the target box and label,
// so the source of a large error shows.
#include <cmath>
#include <cstdio>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/eval/tracker_accuracy.h"
#include "common/frontend/tracker_options.h"
#include "bench/rendered_scenario_args.h"
#include "common/process/arg_parser.h"
#include "common/sim/sim_config.h"

namespace {

using namespace vimot;

void row(const std::string& name, const std::vector<eval::ObservationError>& all,
         const std::function<bool(const eval::ObservationError&)>& keep) {
  std::vector<eval::ObservationError> sel;
  double sum2 = 0.0;
  int64_t inliers = 0;
  for (const auto& e : all) {
    if (!keep(e)) continue;
    sel.push_back(e);
    if (e.error_px <= 3.0) sum2 += e.error_px * e.error_px, ++inliers;
  }
  const eval::ErrorSummary s = eval::summarise(sel);
  // σ per axis of the errors <= 3 px: what the estimator's sigma_px models.
  const double sigma = inliers > 0 ? std::sqrt(sum2 / (2.0 * static_cast<double>(inliers))) : 0.0;
  std::printf("%-28s %8lld %8.3f %8.3f %9.4f %9.3f\n", name.c_str(), static_cast<long long>(s.count), s.median_px,
              s.p95_px, s.outlier_fraction, sigma);
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-tracker-accuracy",
                 "Feature tracker pixel error on rendered images against the true correspondences: each\n"
                 "observation after a track's first against the true point (the first observation's ray\n"
                 "meeting the scene) projected through the true pose. Median, p95, fraction > 3 px and the\n"
                 "per-axis sigma of the errors <= 3 px, by camera, age, box distance and label.");
  add_rendered_scenario_options(args, "config/sim_paper.yaml", "config/feature_tracker_sim.yaml", "30");
  if (!args.parse(argc, argv)) return 0;
  const RenderedScenario scenario = rendered_scenario_from(args);
  const sim::Simulator sim(scenario.sim);
  const frontend::FeatureTrackerOptions& options = scenario.tracker;
  eval::PixelFrontEnd front(sim, options);
  const std::vector<eval::ObservationError> e = eval::tracker_errors(sim, &front, sim.camera_frame_count());

  std::printf("vimot-bench-tracker-accuracy: %s seed %s, %s s, %lld frames, tracker %s\n\n", args.get("sim").c_str(),
              args.get("seed").c_str(), args.get("duration").c_str(),
              static_cast<long long>(sim.camera_frame_count()), args.get("tracker").c_str());
  std::printf("%-28s %8s %8s %8s %9s %9s\n", "observations", "count", "median", "p95", ">3px", "sigma<=3");
  using E = eval::ObservationError;
  auto stat = [](const E& x) { return !x.is_target; };
  row("static, all", e, stat);
  row("static, left (temporal)", e, [&](const E& x) { return stat(x) && x.camera_id == 0; });
  row("static, right (stereo)", e, [&](const E& x) { return stat(x) && x.camera_id == 1; });
  row("static, right, age 0", e, [&](const E& x) { return stat(x) && x.camera_id == 1 && x.age == 0; });
  const int ages[] = {1, 2, 6, 21, 51, 101, 201, 1 << 30};
  for (std::size_t a = 0; a + 1 < std::size(ages); ++a) {
    const std::string name = "static, left, age " + std::to_string(ages[a]) + "-" +
                             (ages[a + 1] == (1 << 30) ? std::string("") : std::to_string(ages[a + 1] - 1));
    row(name, e, [&](const E& x) { return stat(x) && x.camera_id == 0 && x.age >= ages[a] && x.age < ages[a + 1]; });
  }
  row("static, born on target", e, [&](const E& x) { return stat(x) && x.born_on_target; });
  row("static, box dist < 0 (in)", e, [&](const E& x) { return stat(x) && x.box_distance_px <= 0.0; });
  row("static, box dist 0-8 px", e,
      [&](const E& x) { return stat(x) && x.box_distance_px > 0.0 && x.box_distance_px <= 8.0; });
  row("static, box dist 8-20 px", e,
      [&](const E& x) { return stat(x) && x.box_distance_px > 8.0 && x.box_distance_px <= 20.0; });
  row("static, box dist > 20 px", e,
      [&](const E& x) { return stat(x) && x.box_distance_px > 20.0 && std::isfinite(x.box_distance_px); });
  row("static, no box", e, [&](const E& x) { return stat(x) && !std::isfinite(x.box_distance_px); });
  row("target, all", e, [](const E& x) { return x.is_target; });
  row("target, born off target", e, [](const E& x) { return x.is_target && !x.born_on_target; });
  for (int a = 0; a + 1 < 6; ++a) {
    const std::string name = "target, age " + std::to_string(ages[a]) + "-" +
                             (ages[a + 1] == (1 << 30) ? std::string("") : std::to_string(ages[a + 1] - 1));
    row(name, e, [&](const E& x) { return x.is_target && x.age >= ages[a] && x.age < ages[a + 1]; });
    // The same without the tracks born on the room seen past the target's
    // silhouette: the tracker's drift apart from its labelling.
    row(name + ", born on", e,
        [&](const E& x) { return x.is_target && x.born_on_target && x.age >= ages[a] && x.age < ages[a + 1]; });
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-tracker-accuracy", argc, argv, run); }

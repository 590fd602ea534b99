// vimot-bench-target-tracks: what the monocular object tracker gets from
// pixels. The rendered simulator's cam0 through the feature tracker (true
// box), then the object tracker with that box. Per frame: the box size, the
// target features, the features common with the frame `lag` frames before
// (what the object tracker's initialisation needs: min_init_features common
// to the first and last of init_frames); the target track lengths; the
// object tracker's valid frames and counters.
#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/eval/pixel_frontend.h"
#include "common/frontend/tracker_options.h"
#include "common/object/object_tracker.h"
#include "bench/rendered_scenario_args.h"
#include "common/process/arg_parser.h"
#include "common/sim/sim_config.h"
#include "common/time/utime.h"

namespace {

using namespace vimot;

struct Quantiles {
  double min{0}, median{0}, p95{0}, max{0};
};
Quantiles quantiles(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  return {v.front(), v[v.size() / 2], v[(v.size() * 95) / 100], v.back()};
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-target-tracks",
                 "Target features from pixels on the rendered mono scenario (true box) and what the\n"
                 "object tracker makes of them: box size, target features per frame, features common\n"
                 "with the frame --lag before (the initialisation's need), track lengths, tracker\n"
                 "valid frames and counters.");
  add_rendered_scenario_options(args, "config/sim_mono.yaml", "config/feature_tracker_sim_mono.yaml", "20");
  args.add_option("object-tracker", "FILE", "object tracker config", "config/object_tracker.yaml");
  args.add_option("lag", "N", "frames between the compared frames (object tracker init_frames - 1)", "39");
  if (!args.parse(argc, argv)) return 0;
  const RenderedScenario scenario = rendered_scenario_from(args);
  const sim::Simulator sim(scenario.sim);
  const frontend::FeatureTrackerOptions& options = scenario.tracker;
  ObjectTracker object(object_tracker_options_from_config(Config::load_file(args.get("object-tracker"))));
  eval::PixelFrontEnd front(sim, options);
  const int lag = static_cast<int>(args.get_int("lag"));

  std::vector<std::set<int64_t>> ids_per_frame;
  std::map<int64_t, int> track_length;
  std::vector<double> box_w, box_h, n_target, n_common;
  // CPU time of process() per frame, apart while tracking and before (the
  // initialisation's BA runs on every buffered frame until it commits).
  std::vector<double> ms_tracking, ms_initialising;
  int64_t valid = 0, first_valid = -1;
  const int64_t frames = sim.camera_frame_count();
  for (int64_t k = 0; k < frames; ++k) {
    const int64_t utime = sim.camera_utime(k);
    const CameraFrame frame = front.frame(utime);
    std::set<int64_t> ids;
    for (const FeatureObservation& f : frame.observations) {
      if (f.camera_id == 0 && f.is_target) ids.insert(f.feature_id), ++track_length[f.feature_id];
    }
    const sim::RenderedView& view = front.last_views().front();
    std::optional<BoundingBox2d> box;
    if (view.visible) {
      box_w.push_back(view.box[2]);
      box_h.push_back(view.box[3]);
      box = BoundingBox2d{view.box.head<2>(), view.box.head<2>() + view.box.tail<2>()};
    }
    n_target.push_back(static_cast<double>(ids.size()));
    if (static_cast<int>(ids_per_frame.size()) >= lag) {
      const std::set<int64_t>& old = ids_per_frame[ids_per_frame.size() - static_cast<std::size_t>(lag)];
      n_common.push_back(static_cast<double>(
          std::count_if(ids.begin(), ids.end(), [&old](int64_t id) { return old.count(id) != 0; })));
    }
    ids_per_frame.push_back(ids);
    const bool was_tracking = object.init_facts() && valid > 0;
    const double cpu0 = thread_cpu_ms();
    const ObjectPoseEstimate p = object.process(frame, box);
    (was_tracking ? ms_tracking : ms_initialising).push_back(thread_cpu_ms() - cpu0);
    if (p.valid) {
      ++valid;
      if (first_valid < 0) first_valid = k;
    }
  }
  std::vector<double> lengths;
  for (const auto& [id, n] : track_length) lengths.push_back(n);
  const auto print = [](const char* name, const std::vector<double>& v) {
    const Quantiles q = quantiles(v);
    std::printf("%-40s %8.1f %8.1f %8.1f %8.1f\n", name, q.min, q.median, q.p95, q.max);
  };
  std::printf("vimot-bench-target-tracks: %s seed %s, %s s, %lld frames, tracker %s\n\n", args.get("sim").c_str(),
              args.get("seed").c_str(), args.get("duration").c_str(), static_cast<long long>(frames),
              args.get("tracker").c_str());
  std::printf("%-40s %8s %8s %8s %8s\n", "per frame", "min", "median", "p95", "max");
  print("box width [px]", box_w);
  print("box height [px]", box_h);
  print("target features (cam0)", n_target);
  print(("common with frame k-" + std::to_string(lag)).c_str(), n_common);
  print("target track length [frames]", lengths);
  const auto at_least = [&lengths](double n) {
    return std::count_if(lengths.begin(), lengths.end(), [n](double l) { return l >= n; });
  };
  std::printf("target tracks %zu, >= 10 frames %ld, >= %d frames %ld\n", lengths.size(), at_least(10), lag + 1,
              at_least(lag + 1));
  print("object tracker CPU ms, initialising", ms_initialising);
  print("object tracker CPU ms, tracking", ms_tracking);
  const ObjectTrackerCounters& c = object.counters();
  std::printf("object tracker: valid %lld / %lld frames (first at frame %lld), initialisations %lld, losses %lld\n",
              static_cast<long long>(valid), static_cast<long long>(frames), static_cast<long long>(first_valid),
              static_cast<long long>(c.initialisations), static_cast<long long>(c.track_losses));
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-target-tracks", argc, argv, run); }

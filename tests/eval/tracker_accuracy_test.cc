// The feature tracker on rendered stereo pairs against the true
// correspondences (common/eval/tracker_accuracy.h): the shipped rendered
// configs (config/sim_paper.yaml, config/feature_tracker_sim.yaml), 3 s.
// The bounds are the noise model the estimator assumes (config/vins.yaml
// sigma_px = 1 px per axis, white): the error norm is then Rayleigh, with
// median 1.18 px, 95th percentile 2.45 px and P(> 3 px) = exp(-4.5) = 1.1 %.
#include <catch2/catch.hpp>

#include <cmath>
#include <string>

#include "common/config/config.h"
#include "common/eval/tracker_accuracy.h"
#include "common/sim/sim_config.h"

using namespace vimot;

namespace {

const std::string kSource = VIMOT_SOURCE_DIR;

sim::SimConfig paper_config(double duration_s) {
  sim::SimConfig c = sim::from_config(Config::load_file(kSource + "/config/sim_paper.yaml"));
  c.duration = duration_s;
  return c;
}

frontend::FeatureTrackerOptions tracker_options() {
  return frontend::FeatureTrackerOptions::from_config(
      Config::load_file(kSource + "/config/feature_tracker_sim.yaml"), "tracker");
}

}  // namespace

TEST_CASE("Renderer::surface_at agrees with the rendered mask", "[eval][tracker_accuracy]") {
  const sim::Simulator sim(paper_config(1.0));
  const sim::Renderer renderer(sim);
  const int64_t utime = sim.camera_utime(5);
  const std::vector<sim::RenderedView> views = renderer.render(utime);
  int on_target = 0, checked = 0;
  for (const sim::RenderedView& view : views) {
    REQUIRE(view.visible);
    for (int v = 2; v < view.mask.rows - 2; v += 7) {
      for (int u = 2; u < view.mask.cols - 2; u += 7) {
        const uint8_t m = view.mask.at<uint8_t>(v, u);
        // Off the silhouette only: there float and double ray casts agree.
        if (view.mask.at<uint8_t>(v, u - 2) != m || view.mask.at<uint8_t>(v, u + 2) != m ||
            view.mask.at<uint8_t>(v - 2, u) != m || view.mask.at<uint8_t>(v + 2, u) != m) {
          continue;
        }
        const auto hit = renderer.surface_at(view.camera_id, utime, Eigen::Vector2d(u, v));
        CHECK(hit.on_target == (m != 0));
        on_target += hit.on_target ? 1 : 0;
        ++checked;
      }
    }
  }
  CHECK(on_target > 0);
  CHECK(checked > on_target);
}

TEST_CASE("Static tracks on rendered pairs stay within the estimator's pixel noise", "[eval][tracker_accuracy]") {
  const sim::Simulator sim(paper_config(3.0));
  const frontend::FeatureTrackerOptions options = tracker_options();
  REQUIRE(options.static_tracks.max_track_frames > 0);
  eval::PixelFrontEnd front(sim, options);
  const std::vector<eval::ObservationError> all = eval::tracker_errors(sim, &front, sim.camera_frame_count());
  std::vector<eval::ObservationError> statics, stereo_new;
  for (const eval::ObservationError& e : all) {
    if (e.is_target) continue;
    // A static feature never starts on the target (the box and its margin).
    CHECK_FALSE(e.born_on_target);
    CHECK(e.age < options.static_tracks.max_track_frames);
    statics.push_back(e);
    if (e.camera_id == 1 && e.age == 0) stereo_new.push_back(e);
  }
  const eval::ErrorSummary s = eval::summarise(statics);
  INFO("static: " << s.count << " observations, median " << s.median_px << " px, p95 " << s.p95_px
                  << " px, > 3 px " << s.outlier_fraction);
  REQUIRE(s.count > 3000);  // ~150 tracks a frame over 30 frames
  CHECK(s.median_px < 1.18);
  CHECK(s.p95_px < 2.45);
  CHECK(s.outlier_fraction < 0.011);
  // Left-right matches of new corners: the EuRoC epipolar bound.
  const eval::ErrorSummary st = eval::summarise(stereo_new);
  INFO("stereo, new: " << st.count << " observations, median " << st.median_px << " px");
  REQUIRE(st.count > 100);
  CHECK(st.median_px < 0.5);
}

TEST_CASE("summarise: median, nearest-rank p95 and the > 3 px fraction", "[eval][tracker_accuracy]") {
  std::vector<eval::ObservationError> e(20);
  for (int i = 0; i < 20; ++i) e[static_cast<std::size_t>(i)].error_px = i + 1;  // 1 .. 20 px
  const eval::ErrorSummary s = eval::summarise(e);
  CHECK(s.count == 20);
  CHECK(s.median_px == 10.0);
  CHECK(s.p95_px == 19.0);
  CHECK(s.outlier_fraction == Approx(17.0 / 20.0));
  CHECK(eval::summarise({}).count == 0);
}

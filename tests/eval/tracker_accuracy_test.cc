// The feature tracker on rendered stereo pairs against the true
// correspondences (common/eval/tracker_accuracy.h): the shipped rendered
// configs (config/sim_paper.yaml, config/feature_tracker_sim.yaml), 3-6 s;
// the mono scenario with target.use_mask against its true mask.
// The bounds are the noise model the estimator assumes (config/vins.yaml
// sigma_px = 1 px per axis, white): the error norm is then Rayleigh, with
// median 1.18 px, 95th percentile 2.45 px and P(> 3 px) = exp(-4.5) = 1.1 %.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

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

TEST_CASE("Anchored static tracks do not drift with age on rendered frames", "[eval][tracker_accuracy]") {
  // The shipped rendered config aligns each track to its anchor patch; the
  // same run without it is frame-to-frame KLT, whose error accumulates.
  const sim::Simulator sim(paper_config(6.0));
  frontend::FeatureTrackerOptions anchored = tracker_options();
  REQUIRE(anchored.static_tracks.anchor_align);
  frontend::FeatureTrackerOptions plain = anchored;
  plain.static_tracks.anchor_align = false;
  auto left_by_age = [&](const frontend::FeatureTrackerOptions& options, int from, int to) {
    eval::PixelFrontEnd front(sim, options);
    std::vector<eval::ObservationError> young, old;
    for (const eval::ObservationError& e : eval::tracker_errors(sim, &front, sim.camera_frame_count())) {
      if (e.is_target || e.camera_id != 0) continue;
      if (e.age >= 1 && e.age <= 5) young.push_back(e);
      if (e.age >= from && e.age <= to) old.push_back(e);
    }
    return std::make_pair(eval::summarise(young), eval::summarise(old));
  };
  // Tracks older than 20 frames, up to the config's cap or the run's end.
  const int cap = anchored.static_tracks.max_track_frames;
  const int last = cap > 0 ? cap - 1 : 60;
  const auto [a_young, a_old] = left_by_age(anchored, 21, last);
  const auto [p_young, p_old] = left_by_age(plain, 21, last);
  INFO("anchored: age 1-5 median " << a_young.median_px << " px, age 21-" << last << " median " << a_old.median_px
                                   << " px p95 " << a_old.p95_px << " px (" << a_old.count << ")");
  INFO("frame to frame: age 1-5 median " << p_young.median_px << " px, age 21-" << last << " median "
                                         << p_old.median_px << " px p95 " << p_old.p95_px << " px (" << p_old.count
                                         << ")");
  REQUIRE(a_old.count > 1000);
  REQUIRE(p_old.count > 1000);
  // Young tracks: the same (anchoring only corrects what KLT accumulated).
  CHECK(a_young.median_px <= p_young.median_px);
  // Old tracks: at least twice as accurate as frame to frame, and within
  // the estimator's noise model (Rayleigh bounds for σ = 1 px).
  CHECK(a_old.median_px < 0.5 * p_old.median_px);
  CHECK(a_old.p95_px < 0.5 * p_old.p95_px);
  CHECK(a_old.median_px < 1.18);
  CHECK(a_old.p95_px < 2.45);
  CHECK(a_old.outlier_fraction < 0.011);
}

TEST_CASE("Target tracks on rendered pairs are long and sub-pixel", "[eval][tracker_accuracy]") {
  // The shipped rendered config follows target points by KLT, anchored, and
  // finds their right partners by KLT; ORB re-detected and matched by
  // descriptor in every frame and camera (the tracker's default) is the
  // reference: its tracks are short and its keypoints err by ~0.8 px.
  const sim::Simulator sim(paper_config(4.0));
  const frontend::FeatureTrackerOptions shipped = tracker_options();
  REQUIRE(shipped.target.klt());
  REQUIRE(shipped.target.stereo_klt());
  REQUIRE(shipped.target.anchor_align);
  frontend::FeatureTrackerOptions orb = shipped;
  orb.target.frame_to_frame = "orb";
  orb.target.stereo = "descriptor";
  orb.target.anchor_align = false;
  struct Figures {
    eval::ErrorSummary on_target, stereo_new;
    // Share of the on-target observations whose track is 10 frames old or
    // more: it has spanned the estimator's 11-clone window (config/vins.yaml).
    double window_share{0.0};
  };
  auto figures = [&](const frontend::FeatureTrackerOptions& options) {
    eval::PixelFrontEnd front(sim, options);
    std::vector<eval::ObservationError> on_target, stereo_new;
    for (const eval::ObservationError& e : eval::tracker_errors(sim, &front, sim.camera_frame_count())) {
      // Box corners show the room behind the target: not the target's points.
      if (!e.is_target || !e.born_on_target) continue;
      on_target.push_back(e);
      if (e.camera_id == 1 && e.age == 0) stereo_new.push_back(e);
    }
    Figures f;
    f.on_target = eval::summarise(on_target);
    f.stereo_new = eval::summarise(stereo_new);
    const auto old = std::count_if(on_target.begin(), on_target.end(),
                                   [](const eval::ObservationError& e) { return e.age >= 10; });
    if (!on_target.empty()) f.window_share = static_cast<double>(old) / static_cast<double>(on_target.size());
    return f;
  };
  const Figures k = figures(shipped);
  const Figures o = figures(orb);
  INFO("KLT: " << k.on_target.count << " obs., median " << k.on_target.median_px << " px, p95 " << k.on_target.p95_px
               << " px, > 3 px " << k.on_target.outlier_fraction << ", age >= 10: " << k.window_share
               << "; new stereo median " << k.stereo_new.median_px << " px (" << k.stereo_new.count << ")");
  INFO("ORB: " << o.on_target.count << " obs., median " << o.on_target.median_px << " px, p95 " << o.on_target.p95_px
               << " px, age >= 10: " << o.window_share << "; new stereo median " << o.stereo_new.median_px << " px ("
               << o.stereo_new.count << ")");
  REQUIRE(k.on_target.count > 1000);  // ~100 target observations a frame over 40 frames
  REQUIRE(o.on_target.count > 1000);
  // Long tracks: most observations come from tracks that spanned the window.
  CHECK(k.window_share > 0.5);
  CHECK(k.window_share > o.window_share);
  // Within the estimator's 1 px noise model (Rayleigh bounds, see the top),
  // and at least twice as accurate as the ORB keypoints.
  CHECK(k.on_target.median_px < 1.18);
  CHECK(k.on_target.p95_px < 2.45);
  CHECK(k.on_target.outlier_fraction < 0.011);
  CHECK(k.on_target.median_px < 0.5 * o.on_target.median_px);
  // Left-right by KLT: the static stereo bound.
  REQUIRE(k.stereo_new.count > 50);
  CHECK(k.stereo_new.median_px < 0.5);
}

TEST_CASE("Anchored target tracks on rendered mono frames do not drift with age", "[eval][tracker_accuracy]") {
  // The mono scale scenario's config follows target points by KLT and
  // aligns each to its anchor patch; the same run without the anchors is
  // frame-to-frame KLT (3 px median, 55 px p95 at ages 21-50, measured).
  sim::SimConfig config = sim::from_config(Config::load_file(kSource + "/config/sim_mono.yaml"));
  config.duration = 5.0;
  const sim::Simulator sim(config);
  const frontend::FeatureTrackerOptions anchored = frontend::FeatureTrackerOptions::from_config(
      Config::load_file(kSource + "/config/feature_tracker_sim_mono.yaml"), "tracker");
  REQUIRE(anchored.target.klt());
  REQUIRE(anchored.target.anchor_align);
  frontend::FeatureTrackerOptions plain = anchored;
  plain.target.anchor_align = false;
  // Target tracks born on the target, ages 21-50 (the object tracker's
  // initialisation spans 40 frames).
  auto old_on_target = [&](const frontend::FeatureTrackerOptions& options) {
    eval::PixelFrontEnd front(sim, options);
    std::vector<eval::ObservationError> old;
    for (const eval::ObservationError& e : eval::tracker_errors(sim, &front, sim.camera_frame_count())) {
      if (e.is_target && e.born_on_target && e.age >= 21 && e.age <= 50) old.push_back(e);
    }
    return eval::summarise(old);
  };
  const eval::ErrorSummary a = old_on_target(anchored);
  const eval::ErrorSummary p = old_on_target(plain);
  INFO("anchored: age 21-50 median " << a.median_px << " px p95 " << a.p95_px << " px > 3 px " << a.outlier_fraction
                                     << " (" << a.count << ")");
  INFO("frame to frame: age 21-50 median " << p.median_px << " px p95 " << p.p95_px << " px > 3 px "
                                           << p.outlier_fraction << " (" << p.count << ")");
  REQUIRE(a.count > 500);
  REQUIRE(p.count > 500);
  CHECK(a.median_px < 0.5 * p.median_px);
  CHECK(a.p95_px < 0.5 * p.p95_px);
  // Within the estimator's noise model (Rayleigh for sigma = 1 px).
  CHECK(a.median_px < 1.18);
  CHECK(a.p95_px < 2.45);
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

TEST_CASE("PixelFrontEnd with target.use_mask: each target point's window lies on the true mask",
          "[eval][tracker_accuracy]") {
  // The mono rendered scenario; the front end hands the tracker the view's
  // true mask, as the node gets TARGET_MASK_TRUTH. Checked against that
  // mask pixel by pixel: every pixel a 15 px KLT window around the point
  // samples (±8 around its rounded pixel) is on the target.
  sim::SimConfig c = sim::from_config(Config::load_file(kSource + "/config/sim_mono.yaml"));
  c.duration = 1.5;
  const sim::Simulator sim(c);
  frontend::FeatureTrackerOptions options = frontend::FeatureTrackerOptions::from_config(
      Config::load_file(kSource + "/config/feature_tracker_sim_mono.yaml"), "tracker");
  options.target.use_mask = true;
  REQUIRE(options.static_tracks.klt_window_px == 15);
  eval::PixelFrontEnd front(sim, options);
  int targets = 0, off = 0;
  for (int64_t k = 0; k < sim.camera_frame_count(); ++k) {
    const CameraFrame f = front.frame(sim.camera_utime(k));
    const cv::Mat& mask = front.last_views().at(0).mask;
    for (const FeatureObservation& o : f.observations) {
      if (!o.is_target) continue;
      ++targets;
      const int u0 = static_cast<int>(std::lround(o.pixel.x())), v0 = static_cast<int>(std::lround(o.pixel.y()));
      bool on = true;
      for (int v = v0 - 8; v <= v0 + 8 && on; ++v) {
        for (int u = u0 - 8; u <= u0 + 8 && on; ++u) {
          on = u >= 0 && v >= 0 && u < mask.cols && v < mask.rows && mask.at<uint8_t>(v, u) != 0;
        }
      }
      off += on ? 0 : 1;
    }
  }
  INFO(targets << " target observations, " << off << " with a window off the true mask");
  CHECK(targets > 100);
  CHECK(off == 0);
}

// FeatureTracker against images with known truth: a textured plane rendered
// through the real EuRoC stereo calibration (radtan) and through a fisheye
// (equidistant) camera from known poses, so every tracked pixel has an
// exact true correspondence; and a textured target patch pasted at known
// places for the box, ORB and loop-closure behaviour.
#include "common/frontend/feature_tracker.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/frontend/tracking_stats.h"
#include "tests/frontend/synthetic_images.h"

using namespace vimot;
using frontend::Box;
using frontend::FeatureTracker;
using frontend::FeatureTrackerOptions;

namespace {

std::vector<CameraCalibration> euroc_cameras() {
  const Config cfg = Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/euroc_stereo.yaml");
  return {camera_from_config(cfg.sub("cameras.cam0")), camera_from_config(cfg.sub("cameras.cam1"))};
}

struct Pose {
  Eigen::Matrix3d R{Eigen::Matrix3d::Identity()};  // R_WtoC
  Eigen::Vector3d p{Eigen::Vector3d::Zero()};      // p_WinC
};

// Camera 1's pose from camera 0's and the rig extrinsics.
Pose right_of(const Pose& left, const CameraCalibration& c0, const CameraCalibration& c1) {
  const Eigen::Matrix3d R01 = c1.R_ItoC * c0.R_ItoC.transpose();
  const Eigen::Vector3d p01 = c1.p_IinC - R01 * c0.p_IinC;
  return {R01 * left.R, R01 * left.p + p01};
}

std::map<int64_t, Eigen::Vector2d> pixels_of(const CameraFrame& f, int camera, bool target) {
  std::map<int64_t, Eigen::Vector2d> out;
  for (const FeatureObservation& o : f.observations) {
    if (o.camera_id == camera && o.is_target == target) out.emplace(o.feature_id, o.pixel);
  }
  return out;
}

struct Agreement {
  int matches{0};
  double inlier_ratio{0.0};  // share within 1 px of the truth
  double median_px{0.0};
};

// Observations of the same id in (frame a, camera ca) and (frame b, camera
// cb) against the plane's true transfer.
Agreement against_truth(const test::TexturedPlane& plane, const CameraFrame& fa, int ca, const CameraModel& cam_a,
                        const Pose& pa, const CameraFrame& fb, int cb, const CameraModel& cam_b, const Pose& pb) {
  const auto a = pixels_of(fa, ca, false), b = pixels_of(fb, cb, false);
  std::vector<double> err;
  for (const auto& [id, px] : b) {
    const auto it = a.find(id);
    if (it == a.end()) continue;
    err.push_back((plane.transfer(cam_a, pa.R, pa.p, it->second, cam_b, pb.R, pb.p) - px).norm());
  }
  Agreement g;
  g.matches = static_cast<int>(err.size());
  if (err.empty()) return g;
  g.inlier_ratio = static_cast<double>(std::count_if(err.begin(), err.end(), [](double e) { return e < 1.0; })) /
                   static_cast<double>(err.size());
  g.median_px = frontend::median(err);
  return g;
}

}  // namespace

TEST_CASE("stereo tracks of a rendered plane match the true correspondences (EuRoC calibration, radtan)") {
  const std::vector<CameraCalibration> calib = euroc_cameras();
  const CameraModel cam0(calib[0]), cam1(calib[1]);
  test::TexturedPlane plane{test::make_texture(1000, 800, 11, 3000)};
  // Frame 1: the rig moved 3 cm and turned 0.6 degrees, a 20 Hz hand-held step.
  Pose l0, l1;
  l1.R = Eigen::AngleAxisd(0.01, Eigen::Vector3d(0.3, 1.0, 0.2).normalized()).toRotationMatrix();
  l1.p = Eigen::Vector3d(-0.02, 0.01, -0.02);
  const Pose r0 = right_of(l0, calib[0], calib[1]), r1 = right_of(l1, calib[0], calib[1]);

  // Frame-to-frame KLT alone, and refined against each track's anchor patch.
  FeatureTrackerOptions options;
  options.static_tracks.anchor_align = GENERATE(false, true);
  INFO("anchor_align " << options.static_tracks.anchor_align);
  FeatureTracker tracker(options, calib);
  const CameraFrame f0 =
      tracker.track(1000, plane.render(cam0, l0.R, l0.p), plane.render(cam1, r0.R, r0.p), std::nullopt, std::nullopt);
  const CameraFrame f1 =
      tracker.track(51000, plane.render(cam0, l1.R, l1.p), plane.render(cam1, r1.R, r1.p), std::nullopt, std::nullopt);
  CHECK(f1.utime == 51000);

  // KLT on a smooth warp is sub-pixel; 95 % within 1 px leaves room for
  // corners on texture edges that the warp shears.
  const Agreement temporal = against_truth(plane, f0, 0, cam0, l0, f1, 0, cam0, l1);
  INFO("temporal: " << temporal.matches << " matches, inlier ratio " << temporal.inlier_ratio << ", median "
                    << temporal.median_px << " px");
  CHECK(temporal.matches >= 150);
  CHECK(temporal.inlier_ratio >= 0.95);
  CHECK(temporal.median_px < 0.2);

  for (const CameraFrame* f : {&f0, &f1}) {
    const Pose& l = f == &f0 ? l0 : l1;
    const Pose& r = f == &f0 ? r0 : r1;
    const Agreement stereo = against_truth(plane, *f, 0, cam0, l, *f, 1, cam1, r);
    INFO("stereo: " << stereo.matches << " matches, inlier ratio " << stereo.inlier_ratio << ", median "
                    << stereo.median_px << " px");
    CHECK(stereo.matches >= 100);
    CHECK(stereo.inlier_ratio >= 0.95);
    CHECK(stereo.median_px < 0.2);
  }

  // Normalized coordinates are the undistorted rays of the pixels.
  for (const FeatureObservation& o : f1.observations) {
    const CameraModel& cam = o.camera_id == 0 ? cam0 : cam1;
    REQUIRE((cam.distort(o.normalized) - o.pixel).norm() < 1e-6);
  }
  // Ids are unique per camera and frame.
  for (int c = 0; c < 2; ++c) {
    std::set<int64_t> ids;
    for (const FeatureObservation& o : f1.observations) {
      if (o.camera_id == c) CHECK(ids.insert(o.feature_id).second);
    }
  }
}

TEST_CASE("mono tracks through a fisheye (equidistant) camera match the true correspondences") {
  CameraCalibration fisheye;
  fisheye.width = 640;
  fisheye.height = 480;
  fisheye.intrinsics << 300.0, 300.0, 320.0, 240.0;
  fisheye.distortion_model = DistortionModel::kEquidistant;
  fisheye.distortion << -0.0073, 0.0434, -0.0405, 0.0076;
  const CameraModel cam(fisheye);
  // The fisheye sees ~65 degrees off axis: a wide, near plane.
  test::TexturedPlane plane{test::make_texture(2000, 1600, 12, 12000), 0.006, 2.0};
  Pose p0, p1;
  p1.R = Eigen::AngleAxisd(0.012, Eigen::Vector3d(1.0, 0.5, 0.0).normalized()).toRotationMatrix();
  p1.p = Eigen::Vector3d(0.02, -0.01, 0.015);
  FeatureTracker tracker(FeatureTrackerOptions{}, {fisheye});
  const CameraFrame f0 = tracker.track(0, plane.render(cam, p0.R, p0.p), cv::Mat(), std::nullopt, std::nullopt);
  const CameraFrame f1 = tracker.track(50000, plane.render(cam, p1.R, p1.p), cv::Mat(), std::nullopt, std::nullopt);
  const Agreement g = against_truth(plane, f0, 0, cam, p0, f1, 0, cam, p1);
  INFO(g.matches << " matches, inlier ratio " << g.inlier_ratio << ", median " << g.median_px << " px");
  CHECK(g.matches >= 150);
  CHECK(g.inlier_ratio >= 0.95);
  CHECK(g.median_px < 0.2);
  for (const FeatureObservation& o : f1.observations) {
    CHECK(o.camera_id == 0);
    REQUIRE((cam.distort(o.normalized) - o.pixel).norm() < 1e-6);
  }
}

namespace {

// A 640x480 pinhole scene: background texture, and a target patch with its
// own texture pasted with its top-left corner at `at` (none if absent).
constexpr int kPatchW = 180, kPatchH = 140;

cv::Mat scene(const cv::Mat& background, const cv::Mat& patch, std::optional<cv::Point> at) {
  cv::Mat img = background.clone();
  if (at) patch.copyTo(img(cv::Rect(at->x, at->y, kPatchW, kPatchH)));
  return img;
}

Box box_at(cv::Point at) {
  return Box{static_cast<double>(at.x), static_cast<double>(at.y), kPatchW - 1.0, kPatchH - 1.0};
}

}  // namespace

TEST_CASE("features inside the target box are ORB target features, outside static; target ids follow the target") {
  const CameraCalibration cam = test::pinhole(640, 480, 400.0);
  const cv::Mat background = test::make_texture(640, 480, 21, 1500);
  const cv::Mat patch = test::make_texture(kPatchW, kPatchH, 22, 150);
  FeatureTracker tracker(FeatureTrackerOptions{}, {cam});
  const cv::Point a0(200, 150), a1(226, 163);  // the target moves (26, 13) px
  const CameraFrame f0 = tracker.track(0, scene(background, patch, a0), cv::Mat(), box_at(a0), std::nullopt);
  const CameraFrame f1 = tracker.track(50000, scene(background, patch, a1), cv::Mat(), box_at(a1), std::nullopt);

  for (const auto& [frame, at] : {std::make_pair(&f0, a0), std::make_pair(&f1, a1)}) {
    int targets = 0;
    for (const FeatureObservation& o : frame->observations) {
      const bool inside = box_at(at).contains(o.pixel.x(), o.pixel.y());
      CHECK(inside == o.is_target);
      targets += o.is_target ? 1 : 0;
    }
    CHECK(targets >= 20);
  }
  // Target points matched frame to frame keep their id and moved with the
  // target (ORB keypoints of upper pyramid levels sit within ~1 px).
  const auto t0 = pixels_of(f0, 0, true), t1 = pixels_of(f1, 0, true);
  const Eigen::Vector2d shift(a1.x - a0.x, a1.y - a0.y);
  int kept = 0, correct = 0;
  for (const auto& [id, px] : t1) {
    const auto it = t0.find(id);
    if (it == t0.end()) continue;
    ++kept;
    correct += (px - it->second - shift).norm() < 2.0 ? 1 : 0;
  }
  INFO(kept << " of " << t1.size() << " target features kept their id, " << correct << " where the target moved");
  CHECK(kept >= static_cast<int>(t1.size()) / 2);
  CHECK(correct >= 0.95 * kept);
  // Static ids never become target ids or the reverse.
  const auto s0 = pixels_of(f0, 0, false);
  for (const auto& [id, px] : t1) CHECK(s0.count(id) == 0);
}

TEST_CASE("target.grid spreads the target features over the box: a shaded half gets its share") {
  // The target's right half at 0.45 of the left's brightness, as a face
  // turned from the light (the rendered mono scenario's default shading).
  const CameraCalibration cam = test::pinhole(640, 480, 400.0);
  const cv::Mat background = test::make_texture(640, 480, 21, 1500);
  cv::Mat patch = test::make_texture(kPatchW, kPatchH, 22, 150);
  cv::Mat shaded = patch(cv::Rect(kPatchW / 2, 0, kPatchW - kPatchW / 2, kPatchH));
  shaded.convertTo(shaded, -1, 0.45);
  const cv::Point at(200, 150);
  const auto halves = [&](int grid) {
    FeatureTrackerOptions options;
    options.target.num_features = 40;
    options.target.grid = grid;
    FeatureTracker tracker(options, {cam});
    const CameraFrame f = tracker.track(0, scene(background, patch, at), cv::Mat(), box_at(at), std::nullopt);
    std::pair<int, int> lit_shaded{0, 0};
    for (const auto& [id, px] : pixels_of(f, 0, true)) {
      (px.x() < at.x + 0.5 * (kPatchW - 1) ? lit_shaded.first : lit_shaded.second) += 1;
    }
    return lit_shaded;
  };
  const auto [lit1, shaded1] = halves(1);
  const auto [lit2, shaded2] = halves(2);
  INFO("grid 1: " << lit1 << " lit, " << shaded1 << " shaded; grid 2: " << lit2 << " lit, " << shaded2 << " shaded");
  // One cell: ORB's Harris ranking (contrast to the fourth power) fills the
  // 40 slots from the lit half.
  CHECK(lit1 + shaded1 == 40);
  CHECK(shaded1 < lit1 / 2);
  // 2 x 2 cells of at most 10: the lit half's two cells hold 20, the
  // shaded half's corners fill the rest.
  CHECK(lit2 <= 20);
  CHECK(shaded2 >= 15);
}

TEST_CASE("target.use_mask: target points only where their KLT window lies wholly on the target mask") {
  // A textured disc (the target) in a box that also holds the textured
  // background around it; the disc moves between the frames.
  const CameraCalibration cam = test::pinhole(640, 480, 400.0);
  const cv::Mat background = test::make_texture(640, 480, 61, 1500);
  const cv::Mat texture = test::make_texture(640, 480, 62, 1500);
  constexpr int kRadius = 55;
  constexpr int kMarginPx = 25;  // of background between the disc and the box
  struct View {
    cv::Mat image, mask;
    Box box;
    Eigen::Vector2d centre;
  };
  const auto view = [&](cv::Point c) {
    View v;
    v.mask = cv::Mat::zeros(480, 640, CV_8UC1);
    cv::circle(v.mask, c, kRadius, cv::Scalar(255), cv::FILLED);
    v.image = background.clone();
    texture.copyTo(v.image, v.mask);
    const int half = kRadius + kMarginPx;
    v.box = Box{c.x - half + 0.0, c.y - half + 0.0, 2.0 * half, 2.0 * half};
    v.centre = Eigen::Vector2d(c.x, c.y);
    return v;
  };
  const View views[2] = {view({300, 220}), view({314, 228})};
  // The truth: a point's window (klt_window_px = 15, ±7.5 px around it) on
  // the disc, i.e. its four corners within the radius (+ 0.5: the disc's
  // pixels are those whose centre is inside).
  const auto window_on_disc = [&](const Eigen::Vector2d& px, const Eigen::Vector2d& centre) {
    for (const double du : {-7.5, 7.5}) {
      for (const double dv : {-7.5, 7.5}) {
        if ((px + Eigen::Vector2d(du, dv) - centre).norm() > kRadius + 0.5) return false;
      }
    }
    return true;
  };
  const auto run = [&](bool use_mask) {
    FeatureTrackerOptions options;
    options.target.frame_to_frame = "klt";
    options.target.use_mask = use_mask;
    FeatureTracker tracker(options, {cam});
    std::pair<int, int> on_off{0, 0};  // target points with the window on / off the disc
    for (int k = 0; k < 2; ++k) {
      const View& v = views[k];
      const CameraFrame f = tracker.track(k * 50000, v.image, cv::Mat(), v.box, std::nullopt, v.mask);
      for (const auto& [id, px] : pixels_of(f, 0, true)) {
        (window_on_disc(px, v.centre) ? on_off.first : on_off.second)++;
      }
    }
    return on_off;
  };
  const auto [on_masked, off_masked] = run(true);
  const auto [on_plain, off_plain] = run(false);
  INFO("with the mask " << on_masked << " on, " << off_masked << " off the disc; without " << on_plain << " on, "
                        << off_plain << " off");
  CHECK(off_masked == 0);
  CHECK(on_masked >= 20);
  CHECK(off_plain >= 10);  // the box's background and the disc's rim hold target points without the mask
}

TEST_CASE("a target that leaves and comes back gets its old ids back (target loop closure)") {
  const CameraCalibration cam = test::pinhole(640, 480, 400.0);
  const cv::Mat background = test::make_texture(640, 480, 31, 1500);
  const cv::Mat patch = test::make_texture(kPatchW, kPatchH, 32, 150);
  FeatureTracker tracker(FeatureTrackerOptions{}, {cam});
  const cv::Point a(120, 100), back(380, 280);
  const CameraFrame f0 = tracker.track(0, scene(background, patch, a), cv::Mat(), box_at(a), std::nullopt);
  // Gone for three frames: no target, no box.
  for (int k = 1; k <= 3; ++k) {
    const CameraFrame gone =
        tracker.track(k * 50000, scene(background, patch, std::nullopt), cv::Mat(), std::nullopt, std::nullopt);
    for (const FeatureObservation& o : gone.observations) CHECK_FALSE(o.is_target);
  }
  CHECK(tracker.loop_closures() == 0);
  const CameraFrame f4 = tracker.track(200000, scene(background, patch, back), cv::Mat(), box_at(back), std::nullopt);

  const auto before = pixels_of(f0, 0, true), after = pixels_of(f4, 0, true);
  const Eigen::Vector2d moved(back.x - a.x, back.y - a.y);
  int reidentified = 0, correct = 0;
  for (const auto& [id, px] : after) {
    const auto it = before.find(id);
    if (it == before.end()) continue;
    ++reidentified;
    correct += (px - it->second - moved).norm() < 2.0 ? 1 : 0;
  }
  INFO(reidentified << " of " << after.size() << " returning target features re-identified, " << correct
                    << " at the right point");
  CHECK(after.size() >= 20);
  CHECK(reidentified >= static_cast<int>(after.size()) / 2);
  CHECK(correct >= 0.95 * reidentified);
  CHECK(tracker.loop_closures() == reidentified);
}

TEST_CASE("the tracker rejects bad input with a message and stays usable") {
  const CameraCalibration cam = test::pinhole(640, 480, 400.0);
  const cv::Mat image = test::make_texture(640, 480, 41, 1500);
  FeatureTracker stereo(FeatureTrackerOptions{}, {cam, cam});
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  CHECK_THAT(message([&] { stereo.track(0, image, cv::Mat(), std::nullopt, std::nullopt); }),
             Catch::Contains("right image is empty"));
  CHECK_THAT(message([&] { stereo.track(0, image, image(cv::Rect(0, 0, 320, 240)), std::nullopt, std::nullopt); }),
             Catch::Contains("320x240") && Catch::Contains("640x480"));
  cv::Mat colour;
  cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  CHECK_THAT(message([&] { stereo.track(0, colour, image, std::nullopt, std::nullopt); }),
             Catch::Contains("8-bit grey"));
  CHECK_THAT(message([&] {
               stereo.track(0, image, image, Box{1.0, 2.0, std::nan(""), 3.0}, std::nullopt);
             }),
             Catch::Contains("left box"));
  CHECK(stereo.track(10, image, image, std::nullopt, std::nullopt).observations.size() > 100);
  CHECK_THAT(message([&] { stereo.track(10, image, image, std::nullopt, std::nullopt); }),
             Catch::Contains("not after"));
  FeatureTracker mono(FeatureTrackerOptions{}, {cam});
  CHECK_THAT(message([&] { mono.track(0, image, image, std::nullopt, std::nullopt); }), Catch::Contains("mono"));
  CHECK_THAT(message([&] { mono.track(0, image, cv::Mat(), std::nullopt, std::nullopt, image(cv::Rect(0, 0, 9, 9))); }),
             Catch::Contains("left mask") && Catch::Contains("640x480"));
  CHECK_THAT(message([&] { mono.track(0, image, cv::Mat(), std::nullopt, std::nullopt, cv::Mat(), image); }),
             Catch::Contains("right mask"));
  CHECK_THROWS_AS(FeatureTracker(FeatureTrackerOptions{}, {}), std::invalid_argument);
}

TEST_CASE("stereo target features share one id in both cameras, at the target's disparity") {
  // A rectified-like rig: cam1 10 cm to the right of cam0, same orientation,
  // so a point's disparity is purely horizontal. The background is the same
  // image in both cameras (a scene at infinity); the target patch sits
  // 24 px further left in the right image (a target 1.7 m away).
  CameraCalibration left = test::pinhole(640, 480, 400.0), right = left;
  right.p_IinC = Eigen::Vector3d(-0.1, 0.0, 0.0);
  const cv::Mat background = test::make_texture(640, 480, 61, 1500);
  const cv::Mat patch = test::make_texture(kPatchW, kPatchH, 62, 150);
  // ORB in both images matched by descriptor (keypoints within ~1 px), or
  // KLT-followed target points found in the right image by KLT, anchored
  // (within the static stereo bound, 0.5 px).
  FeatureTrackerOptions options;
  double tolerance_px = 2.0;
  SECTION("descriptor") {}
  SECTION("klt") {
    options.target.frame_to_frame = "klt";
    options.target.stereo = "klt";
    options.target.anchor_align = true;
    tolerance_px = 0.5;
  }
  FeatureTracker tracker(options, {left, right});
  const cv::Point disparity(24, 0);
  std::map<int64_t, Eigen::Vector2d> first_left;
  for (int k = 0; k < 2; ++k) {
    const cv::Point a(200 + 15 * k, 150 + 8 * k);
    const CameraFrame f = tracker.track(k * 50000, scene(background, patch, a), scene(background, patch, a - disparity),
                                        box_at(a), box_at(a - disparity));
    const auto l = pixels_of(f, 0, true), r = pixels_of(f, 1, true);
    int shared = 0, correct = 0;
    for (const auto& [id, px] : r) {
      const auto it = l.find(id);
      if (it == l.end()) continue;
      ++shared;
      correct += (it->second - px - Eigen::Vector2d(disparity.x, disparity.y)).norm() < tolerance_px ? 1 : 0;
    }
    INFO("frame " << k << ": " << shared << " stereo target points of " << l.size() << " left, " << correct
                  << " at the disparity");
    CHECK(shared >= static_cast<int>(l.size()) / 2);
    CHECK(correct >= 0.95 * shared);
    if (k == 0) first_left = l;
    if (k == 1) {
      int kept = 0;
      for (const auto& [id, px] : l) kept += first_left.count(id);
      CHECK(kept >= static_cast<int>(l.size()) / 2);
    }
  }
}

// Rendered simulator (common/sim/renderer.h) against the camera model and
// the scenario truth: checkerboard corners at known 3D positions appear
// where CameraModel projects them; the mask is the target's projected
// silhouette (convex hull of its projected corners, built independently of
// the renderer's ray cast); the output is a function of the seeds; bad
// render settings are refused with the key named.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/config/config.h"
#include "common/sim/bspline_se3.h"
#include "common/sim/renderer.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

struct CameraPose {
  Eigen::Matrix3d R_GtoC;
  Eigen::Vector3d p_CinG;
};

CameraPose camera_pose(const Simulator& sim, int cam, int64_t utime) {
  const SplineState s = sim.robot_state(sim.sim_time(utime));
  const CameraCalibration& c = sim.cameras()[static_cast<std::size_t>(cam)];
  // p_C = R_ItoC p_I + p_IinC, p_I = R_GtoI (p_G - p_IinG).
  CameraPose pose;
  pose.R_GtoC = c.R_ItoC * s.R_BtoG.transpose();
  pose.p_CinG = s.p_BinG - s.R_BtoG * c.R_ItoC.transpose() * c.p_IinC;
  return pose;
}

Eigen::Matrix4d target_pose(const Simulator& sim, int64_t utime) {
  const SplineState s = *sim.target_state(sim.sim_time(utime));
  return make_se3(s.R_BtoG, s.p_BinG);
}

// The pixel of p_G in camera `cam`, if it is in front (depth > min_depth).
bool project(const Simulator& sim, int cam, const CameraPose& pose, const Eigen::Vector3d& p_G, double min_depth,
             Eigen::Vector2d* pixel) {
  const Eigen::Vector3d p_C = pose.R_GtoC * (p_G - pose.p_CinG);
  if (!(p_C.z() > min_depth)) return false;
  *pixel = sim.camera_models()[static_cast<std::size_t>(cam)].distort(p_C.head<2>() / p_C.z());
  return true;
}

// Paper scenario with checkerboards of 0.25 m squares on every surface, no
// noise, constant exposure. 1/256 m texels: 64 texels per square, 2048-texel
// scene textures hold 16 square pairs; target texel 1/512 m: 128 per square.
SimConfig checker_config() {
  SimConfig c = test::paper_config();
  c.render.scene_texture = SurfaceTexture::kCheckerboard;
  c.render.target_texture = SurfaceTexture::kCheckerboard;
  c.render.texel_size = 1.0 / 256.0;
  c.render.checker_square = 0.25;
  c.render.noise_sigma = 0.0;
  c.render.exposure_amplitude = 0.0;
  return c;
}

struct CornerCheck {
  int tested{0};
  double max_error{0.0};
  double sum_error{0.0};
};

// Refines `predicted` corners in `image` with cv::cornerSubPix started
// (1.3, -0.9) px away, and records the distance to the prediction. Corners
// whose nearest projected neighbour corner is closer than `min_spacing` px
// (too far away to resolve) were filtered by the caller.
void check_corners(const cv::Mat& image, const std::vector<Eigen::Vector2d>& predicted, CornerCheck* out) {
  if (predicted.empty()) return;
  std::vector<cv::Point2f> pts;
  for (const Eigen::Vector2d& p : predicted) {
    pts.emplace_back(static_cast<float>(p.x() + 1.3), static_cast<float>(p.y() - 0.9));
  }
  cv::cornerSubPix(image, pts, cv::Size(5, 5), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 100, 1e-4));
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const double e = std::hypot(pts[k].x - predicted[k].x(), pts[k].y - predicted[k].y());
    ++out->tested;
    out->max_error = std::max(out->max_error, e);
    out->sum_error += e;
  }
}

// True if the 3x3-corner neighbourhood of a corner projects large enough
// (neighbours >= min_spacing px away) and inside the image with a margin.
bool resolvable(const Simulator& sim, int cam, const CameraPose& pose, const Eigen::Vector3d& p,
                const Eigen::Vector3d& step1, const Eigen::Vector3d& step2, Eigen::Vector2d* pixel) {
  constexpr double kMinSpacing = 14.0, kMargin = 16.0;
  const CameraModel& model = sim.camera_models()[static_cast<std::size_t>(cam)];
  if (!project(sim, cam, pose, p, 0.3, pixel) || !model.in_image(*pixel, kMargin)) return false;
  for (const Eigen::Vector3d& step : {step1, Eigen::Vector3d(-step1), step2, Eigen::Vector3d(-step2)}) {
    Eigen::Vector2d q;
    if (!project(sim, cam, pose, p + step, 0.3, &q) || (q - *pixel).norm() < kMinSpacing) return false;
  }
  return true;
}

}  // namespace

TEST_CASE("renderer: checkerboard corners on the floor and on the target appear where CameraModel projects them") {
  const SimConfig config = checker_config();
  const Simulator sim(config);
  const Renderer renderer(sim);
  const double sq = config.render.checker_square;
  const Eigen::Vector3d half = 0.5 * config.target.size;
  CornerCheck floor, target;
  for (int k = 0; k < 6; ++k) {
    const int64_t utime = sim.camera_utime(sim.camera_frame_count() * k / 6);
    const std::vector<RenderedView> views = renderer.render(utime);
    REQUIRE(views.size() == 2);
    const Eigen::Matrix4d T_TtoG = target_pose(sim, utime);
    for (int cam = 0; cam < 2; ++cam) {
      const CameraPose pose = camera_pose(sim, cam, utime);
      cv::Mat near_target;  // keep floor corners clear of the target's silhouette
      cv::dilate(views[static_cast<std::size_t>(cam)].mask, near_target, cv::Mat(), cv::Point(-1, -1), 12);

      // Floor corners (i sq, j sq, 0) within 12 m of the camera.
      std::vector<Eigen::Vector2d> floor_pixels;
      const int i0 = static_cast<int>(std::floor((pose.p_CinG.x() - 12.0) / sq));
      const int j0 = static_cast<int>(std::floor((pose.p_CinG.y() - 12.0) / sq));
      for (int i = i0; i <= i0 + static_cast<int>(24.0 / sq); ++i) {
        for (int j = j0; j <= j0 + static_cast<int>(24.0 / sq); ++j) {
          const Eigen::Vector3d p(i * sq, j * sq, 0.0);
          Eigen::Vector2d px;
          if (!resolvable(sim, cam, pose, p, Eigen::Vector3d(sq, 0, 0), Eigen::Vector3d(0, sq, 0), &px)) continue;
          if (near_target.at<uint8_t>(static_cast<int>(std::lround(px.y())), static_cast<int>(std::lround(px.x()))) != 0) {
            continue;
          }
          floor_pixels.push_back(px);
        }
      }
      check_corners(views[static_cast<std::size_t>(cam)].image, floor_pixels, &floor);

      // Interior corners of the target faces facing the camera.
      std::vector<Eigen::Vector2d> target_pixels;
      const Eigen::Matrix3d R_TtoG = T_TtoG.topLeftCorner<3, 3>();
      const Eigen::Vector3d p_TinG = T_TtoG.topRightCorner<3, 1>();
      for (int axis = 0; axis < 3; ++axis) {
        for (const double sign : {1.0, -1.0}) {
          const Eigen::Vector3d n_G = sign * R_TtoG.col(axis);
          const Eigen::Vector3d centre = p_TinG + sign * half(axis) * R_TtoG.col(axis);
          // Well facing the camera, so the corner's neighbourhood is on this face.
          if (n_G.dot((pose.p_CinG - centre).normalized()) < 0.3) continue;
          const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
          for (double x = -half(a1) + sq; x < half(a1) - 0.5 * sq; x += sq) {
            for (double y = -half(a2) + sq; y < half(a2) - 0.5 * sq; y += sq) {
              Eigen::Vector3d p_T = Eigen::Vector3d::Zero();
              p_T(axis) = sign * half(axis);
              p_T(a1) = x;
              p_T(a2) = y;
              Eigen::Vector2d px;
              if (resolvable(sim, cam, pose, R_TtoG * p_T + p_TinG, sq * R_TtoG.col(a1), sq * R_TtoG.col(a2),
                             &px)) {
                target_pixels.push_back(px);
              }
            }
          }
        }
      }
      check_corners(views[static_cast<std::size_t>(cam)].image, target_pixels, &target);
    }
  }
  INFO("floor corners " << floor.tested << ", mean " << floor.sum_error / std::max(floor.tested, 1) << " px, max "
                        << floor.max_error << " px; target corners " << target.tested << ", mean "
                        << target.sum_error / std::max(target.tested, 1) << " px, max " << target.max_error << " px");
  REQUIRE(floor.tested >= 200);
  REQUIRE(target.tested >= 20);
  CHECK(floor.max_error < 0.5);
  CHECK(target.max_error < 0.5);
}

namespace {

// Compares a rendered mask with the target's silhouette: the convex hull of
// its 8 projected corners on the normalized image plane (the projection of a
// convex box is the hull of its projected corners), tested per pixel through
// CameraModel::undistort. Pixels within `boundary` px of the hull's edge are
// not compared (a pixel is in the mask when its centre ray hits the target).
struct MaskCheck {
  long compared{0};
  long inside{0};
  long mismatched{0};
  double box_error{0.0};  // px, largest difference of the box sides
};

void check_mask(const Simulator& sim, const RenderedView& view, MaskCheck* out) {
  constexpr double kBoundary = 0.75;  // px
  const int cam = view.camera_id;
  const CameraModel& model = sim.camera_models()[static_cast<std::size_t>(cam)];
  const CameraPose pose = camera_pose(sim, cam, view.utime);
  const Eigen::Matrix4d T_TtoG = target_pose(sim, view.utime);
  const Eigen::Vector3d half = 0.5 * sim.config().target.size;
  std::vector<cv::Point2f> corners;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d p_T(c & 1 ? half.x() : -half.x(), c & 2 ? half.y() : -half.y(),
                              c & 4 ? half.z() : -half.z());
    const Eigen::Vector3d p_C = pose.R_GtoC * (T_TtoG.topLeftCorner<3, 3>() * p_T + T_TtoG.topRightCorner<3, 1>() -
                                               pose.p_CinG);
    REQUIRE(p_C.z() > 0.1);
    corners.emplace_back(static_cast<float>(p_C.x() / p_C.z()), static_cast<float>(p_C.y() / p_C.z()));
  }
  std::vector<cv::Point2f> hull;
  cv::convexHull(corners, hull);
  // Pixel bounds of the silhouette from its densely sampled outline.
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const cv::Point2f a = hull[k], b = hull[(k + 1) % hull.size()];
    for (int s = 0; s <= 200; ++s) {
      const double f = s / 200.0;
      const Eigen::Vector2d px = model.distort(Eigen::Vector2d(a.x + f * (b.x - a.x), a.y + f * (b.y - a.y)));
      u0 = std::min(u0, px.x()), u1 = std::max(u1, px.x());
      v0 = std::min(v0, px.y()), v1 = std::max(v1, px.y());
    }
  }
  const cv::Rect region = cv::Rect(static_cast<int>(std::floor(u0)) - 3, static_cast<int>(std::floor(v0)) - 3,
                                   static_cast<int>(u1 - u0) + 7, static_cast<int>(v1 - v0) + 7) &
                          cv::Rect(0, 0, view.mask.cols, view.mask.rows);
  const double focal = model.mean_focal();
  long in_region = 0;
  for (int v = region.y; v < region.y + region.height; ++v) {
    for (int u = region.x; u < region.x + region.width; ++u) {
      const Eigen::Vector2d n = model.undistort(Eigen::Vector2d(u, v));
      // Signed distance to the hull in normalized units (> 0 inside), in px.
      const double d = focal * cv::pointPolygonTest(hull, cv::Point2f(static_cast<float>(n.x()),
                                                                      static_cast<float>(n.y())), true);
      const bool in_mask = view.mask.at<uint8_t>(v, u) != 0;
      in_region += in_mask ? 1 : 0;
      if (std::abs(d) < kBoundary) continue;
      ++out->compared;
      out->inside += d > 0 ? 1 : 0;
      if ((d > 0) != in_mask) ++out->mismatched;
    }
  }
  // No mask pixel outside the silhouette's bounds.
  out->mismatched += cv::countNonZero(view.mask) - in_region;
  // The box spans the pixel centres inside the silhouette, [ceil(u0),
  // floor(u1)] x [ceil(v0), floor(v1)], give or take the one pixel a side's
  // extreme point may fall between two pixel rows (columns).
  REQUIRE(view.visible);
  const Eigen::Vector4d sides(view.box(0), view.box(1), view.box(0) + view.box(2) - 1, view.box(1) + view.box(3) - 1);
  const Eigen::Vector4d expected(std::ceil(u0), std::ceil(v0), std::floor(u1), std::floor(v1));
  out->box_error = std::max(out->box_error, (sides - expected).cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("renderer: the mask is exactly the target's projected silhouette, the box its bounds (paper, mono)") {
  for (const char* file : {"config/sim_paper.yaml", "config/sim_mono.yaml"}) {
    SECTION(file) {
      const SimConfig config = test::load_config(file);
      const Simulator sim(config);
      const Renderer renderer(sim);
      MaskCheck check;
      for (int k = 0; k < 4; ++k) {
        const int64_t utime = sim.camera_utime(sim.camera_frame_count() * k / 4 + 7);
        for (const RenderedView& view : renderer.render(utime)) check_mask(sim, view, &check);
      }
      INFO(file << ": " << check.compared << " pixels compared, " << check.inside << " inside, "
                << check.mismatched << " mismatched, largest box side error " << check.box_error << " px");
      CHECK(check.inside > 5000);
      CHECK(check.mismatched == 0);
      CHECK(check.box_error <= 1.0);
    }
  }
}

TEST_CASE("renderer: the images are a function of the seeds and the utime only") {
  SimConfig config = test::load_config("config/sim_mono.yaml");
  config.render.noise_sigma = 3.0;
  config.render.exposure_amplitude = 0.2;
  const Simulator sim_a(config), sim_b(config);
  const Renderer a(sim_a), b(sim_b);
  const int64_t u1 = sim_a.camera_utime(10), u2 = sim_a.camera_utime(300);
  const std::vector<RenderedView> a1 = a.render(u1), a2 = a.render(u2);
  const std::vector<RenderedView> b2 = b.render(u2), b1 = b.render(u1);  // other order
  auto same = [](const cv::Mat& x, const cv::Mat& y) { return cv::countNonZero(x != y) == 0; };
  CHECK(same(a1[0].image, b1[0].image));
  CHECK(same(a2[0].image, b2[0].image));
  CHECK(same(a1[0].mask, b1[0].mask));
  CHECK_FALSE(same(a1[0].image, a2[0].image));

  // Another noise seed: other noise and exposure, same scene and truth.
  config.seed = 2;
  const Simulator sim_c(config);
  const Renderer c(sim_c);
  const std::vector<RenderedView> c1 = c.render(u1);
  CHECK_FALSE(same(a1[0].image, c1[0].image));
  CHECK(same(a1[0].mask, c1[0].mask));
  CHECK(a1[0].box == c1[0].box);
  // The difference is noise and gain, not another scene: strongly correlated.
  cv::Mat fa, fc;
  a1[0].image.convertTo(fa, CV_64F);
  c1[0].image.convertTo(fc, CV_64F);
  cv::Scalar ma, sa, mc, sc;
  cv::meanStdDev(fa, ma, sa);
  cv::meanStdDev(fc, mc, sc);
  const double corr = cv::mean((fa - ma[0]).mul(fc - mc[0]))[0] / (sa[0] * sc[0]);
  CHECK(corr > 0.9);
}

TEST_CASE("renderer: render.target_ambient shades the target's faces only, between ambient and full light") {
  SimConfig config = test::load_config("config/sim_mono.yaml");
  config.render.noise_sigma = 0.0;
  config.render.exposure_amplitude = 0.0;
  config.render.target_ambient = 1.0;  // every face unshaded: the texture itself
  const Simulator sim_full(config);
  config.render.target_ambient = 0.45;
  const Simulator sim_shaded(config);
  const Renderer full(sim_full), shaded(sim_shaded);
  const int64_t utime = sim_full.camera_utime(100);
  const RenderedView a = full.render(utime).at(0), b = shaded.render(utime).at(0);
  REQUIRE(a.visible);
  // Off the anti-aliased outline, whose pixels on both sides blend target and room.
  cv::Mat inside, near;
  cv::erode(a.mask, inside, cv::Mat());
  cv::dilate(a.mask, near, cv::Mat());
  int pixels = 0, out_of_range = 0, room_differs = 0;
  for (int y = 0; y < a.image.rows; ++y) {
    for (int x = 0; x < a.image.cols; ++x) {
      const int lit = a.image.at<uint8_t>(y, x), dim = b.image.at<uint8_t>(y, x);
      if (near.at<uint8_t>(y, x) == 0) {
        room_differs += lit != dim ? 1 : 0;
      } else if (inside.at<uint8_t>(y, x) != 0) {
        ++pixels;
        // shade = ambient + (1 - ambient) Lambert, in [0.45, 1]; ±1 rounding
        out_of_range += (dim > lit + 1 || dim < 0.45 * lit - 1) ? 1 : 0;
      }
    }
  }
  INFO(pixels << " target pixels, " << out_of_range << " outside [0.45, 1] of the unshaded value");
  CHECK(pixels > 1000);
  CHECK(out_of_range == 0);
  CHECK(room_differs == 0);
  CHECK(cv::countNonZero(a.mask != b.mask) == 0);
}

TEST_CASE("renderer: a scene with features everywhere the cameras look (no blank areas)") {
  // Every 32 x 32 px cell of the image, apart from those the target covers,
  // has texture: grey-level standard deviation above the noise alone.
  for (const char* file : {"config/sim_paper.yaml", "config/sim_mono.yaml"}) {
    SimConfig config = test::load_config(file);
    config.render.noise_sigma = 0.0;
    const Simulator sim(config);
    const Renderer renderer(sim);
    for (int k = 0; k < 3; ++k) {
      const int64_t utime = sim.camera_utime(sim.camera_frame_count() * k / 3);
      for (const RenderedView& view : renderer.render(utime)) {
        int cells = 0, flat = 0;
        for (int y = 0; y + 32 <= view.image.rows; y += 32) {
          for (int x = 0; x + 32 <= view.image.cols; x += 32) {
            const cv::Rect cell(x, y, 32, 32);
            if (cv::countNonZero(view.mask(cell)) > 0) continue;
            cv::Scalar mean, stddev;
            cv::meanStdDev(view.image(cell), mean, stddev);
            ++cells;
            flat += stddev[0] < 4.0 ? 1 : 0;
          }
        }
        INFO(file << " utime " << utime << " camera " << view.camera_id << ": " << flat << " flat of " << cells);
        CHECK(flat == 0);
      }
    }
  }
}

namespace {

std::string render_error_of(const std::string& render_yaml) {
  try {
    from_config(Config::from_string("scenario: paper\ncalibration_file: euroc_stereo.yaml\nrender:\n" + render_yaml,
                                    test::source_path("config/inline_test.yaml")));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("renderer: bad render settings are refused with the key named") {
  CHECK(render_error_of("  texel_size: 0.004\n").empty());
  CHECK_THAT(render_error_of("  texel_size: -0.01\n"), Catch::Contains("render.texel_size") && Catch::Contains("-0.01"));
  CHECK_THAT(render_error_of("  texture_size: 1000\n"),
             Catch::Contains("render.texture_size") && Catch::Contains("power of two"));
  CHECK_THAT(render_error_of("  target_texture_size: 8\n"), Catch::Contains("render.target_texture_size"));
  CHECK_THAT(render_error_of("  noise_sigma: -1\n"), Catch::Contains("render.noise_sigma"));
  CHECK_THAT(render_error_of("  noise_sigma: .nan\n"), Catch::Contains("render.noise_sigma"));
  CHECK_THAT(render_error_of("  exposure_amplitude: 5\n"), Catch::Contains("render.exposure_amplitude"));
  CHECK_THAT(render_error_of("  target_ambient: 1.5\n"), Catch::Contains("render.target_ambient"));
  CHECK_THAT(render_error_of("  scene_texture: bricks\n"),
             Catch::Contains("render.scene_texture") && Catch::Contains("bricks"));
  CHECK_THAT(render_error_of("  noise: 2\n"), Catch::Contains("render.noise") && Catch::Contains("unknown"));
  CHECK_THAT(render_error_of("  scene_texture: checkerboard\n  checker_square: 0.3\n"),
             Catch::Contains("render.checker_square") && Catch::Contains("whole number"));

  SimConfig config = test::paper_config();
  config.render.noise_sigma = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_WITH(validate(config), Catch::Contains("render.noise_sigma"));
}

TEST_CASE("renderer: a camera path leaving the room, or a utime outside the run, is refused") {
  SimConfig config = test::paper_config();
  config.duration = 5.0;
  config.map.margin = 0.0;  // the room is the paths' bounding box: the camera reaches its sides
  {
    const Simulator sim(config);
    CHECK_THROWS_WITH(Renderer(sim), Catch::Contains("leaves the room"));
  }
  config.map.margin = 10.0;
  const Simulator sim(config);
  const Renderer renderer(sim);
  CHECK_THROWS_WITH(renderer.render(sim.end_utime() + 1), Catch::Contains("outside the run"));
  CHECK_NOTHROW(renderer.render(sim.end_utime()));
}

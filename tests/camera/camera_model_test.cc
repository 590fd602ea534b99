// CameraModel checked against independent references: OpenCV's own
// projectPoints / undistortPoints for the radtan model, central finite
// differences for the Jacobian, 4x4 homogeneous-matrix algebra for the
// extrinsics, and the EuRoC dataset files for the default calibration.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "common/camera/camera_model.h"
#include "common/config/config.h"
#include "tests/data_dir.h"

using namespace vimot;

namespace {

const std::string kDefaultCalibration = std::string(VIMOT_SOURCE_DIR) + "/config/euroc_stereo.yaml";

Config default_config() { return Config::load_file(kDefaultCalibration); }

CameraCalibration default_cam(int i) {
  return camera_from_config(default_config().sub("cameras.cam" + std::to_string(i)));
}

// A strongly distorting lens with visible tangential terms, still invertible
// over its whole image (1 + 3 k1 r² + 5 k2 r⁴ > 0 for every r).
CameraCalibration strong_lens() {
  CameraCalibration c;
  c.width = 640;
  c.height = 480;
  c.intrinsics << 300.0, 310.0, 330.0, 235.0;
  c.distortion << -0.4, 0.15, 0.004, -0.003;
  return c;
}

// The mav0 folder of the shared EuRoC excerpt, or "" (the test is then
// reported as skipped, tests/data_dir.h).
std::string euroc_mav0(const std::string& what) {
  const std::string sensor = vimot::test_data_file_or_skip("euroc_v101_micro/mav0/cam0/sensor.yaml", what);
  return sensor.empty() ? "" : sensor.substr(0, sensor.size() - std::string("/cam0/sensor.yaml").size());
}

cv::Matx33d camera_matrix(const CameraCalibration& c) {
  return cv::Matx33d(c.intrinsics(0), 0.0, c.intrinsics(2), 0.0, c.intrinsics(1), c.intrinsics(3), 0.0, 0.0, 1.0);
}

std::vector<double> dist_coeffs(const CameraCalibration& c) {
  return {c.distortion(0), c.distortion(1), c.distortion(2), c.distortion(3)};
}

// Every pixel position of a grid over the whole image, edges and corners
// included (pixel areas reach from -0.5 to width-0.5).
std::vector<Eigen::Vector2d> image_grid(const CameraCalibration& c, double step) {
  std::vector<double> us, vs;
  for (double u = -0.5; u < c.width - 0.5; u += step) us.push_back(u);
  us.push_back(c.width - 0.5);
  for (double v = -0.5; v < c.height - 0.5; v += step) vs.push_back(v);
  vs.push_back(c.height - 0.5);
  std::vector<Eigen::Vector2d> grid;
  for (double u : us)
    for (double v : vs) grid.emplace_back(u, v);
  return grid;
}

template <typename E, typename F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  FAIL("expected an exception, none was thrown");
  return "";
}

const std::string kAslCamera = R"(%YAML:1.0
T_BS:
  cols: 4
  rows: 4
  data: [1.0, 0.0, 0.0, 0.1,
         0.0, 1.0, 0.0, 0.0,
         0.0, 0.0, 1.0, 0.0,
         0.0, 0.0, 0.0, 1.0]
resolution: [752, 480]
camera_model: pinhole
intrinsics: [458.654, 457.296, 367.215, 248.375]
distortion_model: radial-tangential
distortion_coefficients: [-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05]
)";

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto pos = text.find(from);
  REQUIRE(pos != std::string::npos);
  return text.replace(pos, from.size(), to);
}

}  // namespace

TEST_CASE("distort equals OpenCV projectPoints") {
  for (const CameraCalibration& calib : {default_cam(0), default_cam(1), strong_lens()}) {
    const CameraModel cam(calib);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> uni(-1.5, 1.5);
    std::vector<cv::Point3d> rays;
    for (int i = 0; i < 2000; ++i) rays.emplace_back(uni(rng), uni(rng), 1.0);
    std::vector<cv::Point2d> cv_pixels;
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(calib), dist_coeffs(calib),
                      cv_pixels);
    double max_error = 0.0;
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const Eigen::Vector2d p = cam.distort(Eigen::Vector2d(rays[i].x, rays[i].y));
      max_error = std::max(max_error, (p - Eigen::Vector2d(cv_pixels[i].x, cv_pixels[i].y)).norm());
    }
    CHECK(max_error < 1e-9);
  }
}

TEST_CASE("distort_jacobian equals central finite differences") {
  for (const CameraCalibration& calib : {default_cam(0), default_cam(1), strong_lens()}) {
    const CameraModel cam(calib);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> uni(-1.4, 1.4);
    const double h = 1e-6;
    for (int i = 0; i < 200; ++i) {
      const Eigen::Vector2d x(uni(rng), uni(rng));
      Eigen::Matrix2d numeric;
      for (int k = 0; k < 2; ++k) {
        const Eigen::Vector2d dx = h * Eigen::Vector2d::Unit(k);
        numeric.col(k) = (cam.distort(x + dx) - cam.distort(x - dx)) / (2.0 * h);
      }
      const Eigen::Matrix2d J = cam.distort_jacobian(x);
      INFO("x = " << x.transpose() << "\nanalytic\n" << J << "\nnumeric\n" << numeric);
      CHECK((J - numeric).norm() < 1e-6 * J.norm());
    }
  }
}

TEST_CASE("undistort inverts distort over the whole image") {
  for (const CameraCalibration& calib : {default_cam(0), default_cam(1), strong_lens()}) {
    const CameraModel cam(calib);
    // Pixel -> normalized -> pixel on a grid covering every edge and corner.
    double max_pixel_error = 0.0;
    for (const Eigen::Vector2d& p : image_grid(calib, 4.0)) {
      max_pixel_error = std::max(max_pixel_error, (cam.distort(cam.undistort(p)) - p).norm());
    }
    CHECK(max_pixel_error < 1e-9);

    // Normalized -> pixel -> normalized for rays that land in the image.
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> uni(-2.0, 2.0);
    int tested = 0;
    double max_normalized_error = 0.0;
    for (int i = 0; i < 5000; ++i) {
      const Eigen::Vector2d x(uni(rng), uni(rng));
      const Eigen::Vector2d p = cam.distort(x);
      if (!cam.in_image(p, -0.5)) continue;
      ++tested;
      max_normalized_error = std::max(max_normalized_error, (cam.undistort(p) - x).norm());
    }
    CHECK(tested > 500);
    CHECK(max_normalized_error < 1e-12);
  }
}

TEST_CASE("undistort agrees with OpenCV undistortPoints where OpenCV converges") {
  // OpenCV inverts by fixed-point iteration, which converges slowly or not
  // at all near strongly distorted corners; there its result does not
  // re-project onto the pixel, so only points it solved are compared.
  for (const CameraCalibration& calib : {default_cam(0), default_cam(1), strong_lens()}) {
    const CameraModel cam(calib);
    const std::vector<Eigen::Vector2d> grid = image_grid(calib, 8.0);
    std::vector<cv::Point2d> pixels;
    for (const Eigen::Vector2d& p : grid) pixels.emplace_back(p.x(), p.y());
    std::vector<cv::Point2d> cv_normalized;
    cv::undistortPoints(pixels, cv_normalized, camera_matrix(calib), dist_coeffs(calib), cv::noArray(),
                        cv::noArray(), cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-12));
    std::vector<cv::Point3d> rays;
    for (const cv::Point2d& n : cv_normalized) rays.emplace_back(n.x, n.y, 1.0);
    std::vector<cv::Point2d> cv_reprojected;
    cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(calib), dist_coeffs(calib),
                      cv_reprojected);
    int converged = 0;
    double max_error = 0.0;
    for (std::size_t i = 0; i < grid.size(); ++i) {
      const double cv_reprojection_error =
          std::hypot(cv_reprojected[i].x - pixels[i].x, cv_reprojected[i].y - pixels[i].y);
      if (!(cv_reprojection_error < 1e-9)) continue;
      ++converged;
      const Eigen::Vector2d n = cam.undistort(grid[i]);
      max_error = std::max(max_error, (n - Eigen::Vector2d(cv_normalized[i].x, cv_normalized[i].y)).norm());
    }
    INFO("OpenCV converged on " << converged << " of " << grid.size() << " pixels");
    CHECK(converged > static_cast<int>(grid.size()) / 2);
    CHECK(max_error < 1e-10);
  }
}

// A fisheye lens on a 752x480 sensor (Kalibr equidistant coefficients of a
// T265-class lens); its image corners lie 74 degrees off the axis.
CameraCalibration fisheye_lens() {
  CameraCalibration c;
  c.width = 752;
  c.height = 480;
  c.intrinsics << 350.0, 351.0, 380.0, 242.0;
  c.distortion_model = DistortionModel::kEquidistant;
  c.distortion << -0.0073, 0.0434, -0.0405, 0.0076;
  return c;
}

TEST_CASE("equidistant distort equals OpenCV fisheye::distortPoints") {
  const CameraCalibration calib = fisheye_lens();
  const CameraModel cam(calib);
  std::mt19937 rng(6);
  std::uniform_real_distribution<double> uni(-2.5, 2.5);
  std::vector<cv::Point2d> normalized;
  for (int i = 0; i < 2000; ++i) normalized.emplace_back(uni(rng), uni(rng));
  normalized.emplace_back(0.0, 0.0);     // the centre, where θd / r is 0 / 0
  normalized.emplace_back(1e-10, 0.0);   // inside the small-radius branch
  std::vector<cv::Point2d> cv_pixels;
  cv::fisheye::distortPoints(normalized, cv_pixels, camera_matrix(calib), dist_coeffs(calib));
  double max_error = 0.0;
  for (std::size_t i = 0; i < normalized.size(); ++i) {
    const Eigen::Vector2d p = cam.distort(Eigen::Vector2d(normalized[i].x, normalized[i].y));
    max_error = std::max(max_error, (p - Eigen::Vector2d(cv_pixels[i].x, cv_pixels[i].y)).norm());
  }
  CHECK(max_error < 1e-9);
}

TEST_CASE("equidistant distort_jacobian equals central finite differences") {
  const CameraModel cam(fisheye_lens());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(-2.5, 2.5);
  const double h = 1e-6;
  std::vector<Eigen::Vector2d> points{Eigen::Vector2d(0.0, 0.0), Eigen::Vector2d(3e-9, -2e-9)};
  for (int i = 0; i < 200; ++i) points.emplace_back(uni(rng), uni(rng));
  for (const Eigen::Vector2d& x : points) {
    Eigen::Matrix2d numeric;
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector2d dx = h * Eigen::Vector2d::Unit(k);
      numeric.col(k) = (cam.distort(x + dx) - cam.distort(x - dx)) / (2.0 * h);
    }
    const Eigen::Matrix2d J = cam.distort_jacobian(x);
    INFO("x = " << x.transpose() << "\nanalytic\n" << J << "\nnumeric\n" << numeric);
    CHECK((J - numeric).norm() < 1e-6 * J.norm());
  }
}

TEST_CASE("equidistant undistort inverts distort and agrees with OpenCV fisheye::undistortPoints") {
  const CameraCalibration calib = fisheye_lens();
  const CameraModel cam(calib);
  const std::vector<Eigen::Vector2d> grid = image_grid(calib, 8.0);
  std::vector<cv::Point2d> pixels;
  double max_pixel_error = 0.0;
  for (const Eigen::Vector2d& p : grid) {
    pixels.emplace_back(p.x(), p.y());
    max_pixel_error = std::max(max_pixel_error, (cam.distort(cam.undistort(p)) - p).norm());
  }
  CHECK(max_pixel_error < 1e-9);
  std::vector<cv::Point2d> cv_normalized;
  cv::fisheye::undistortPoints(pixels, cv_normalized, camera_matrix(calib), dist_coeffs(calib), cv::noArray(),
                               cv::noArray(),
                               cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-14));
  double max_error = 0.0;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    const Eigen::Vector2d n = cam.undistort(grid[i]);
    max_error = std::max(max_error, (n - Eigen::Vector2d(cv_normalized[i].x, cv_normalized[i].y)).norm());
  }
  CHECK(max_error < 1e-8);
  // 2.2 rad (126 degrees) off the axis: no point on the plane z = 1.
  const std::string msg = message_of<std::runtime_error>([&] { cam.undistort(Eigen::Vector2d(380.0 + 770.0, 242.0)); });
  CHECK_THAT(msg, Catch::Contains("1150") && Catch::Contains("90 degrees"));
}

TEST_CASE("undistort throws naming the pixel where the model has no inverse") {
  // Pure barrel distortion k1 = -0.5 folds over at r = 1/sqrt(1.5): distorted
  // radii beyond 0.544 (218 pixels here) are the image of no ray.
  CameraCalibration c;
  c.width = 800;
  c.height = 800;
  c.intrinsics << 400.0, 400.0, 400.0, 400.0;
  c.distortion << -0.5, 0.0, 0.0, 0.0;
  const CameraModel cam(c);
  const Eigen::Vector2d inside(400.0 + 150.0, 400.0 + 20.0);
  CHECK((cam.distort(cam.undistort(inside)) - inside).norm() < 1e-9);
  const std::string msg = message_of<std::runtime_error>([&] { cam.undistort(Eigen::Vector2d(700.25, 400.0)); });
  CHECK_THAT(msg, Catch::Contains("700.25") && Catch::Contains("400"));
  CHECK_THROWS_AS(cam.undistort(Eigen::Vector2d(std::nan(""), 1.0)), std::runtime_error);
}

TEST_CASE("in_image keeps pixel centres 0..size-1 minus the border") {
  const CameraModel cam(default_cam(0));
  CHECK(cam.in_image(Eigen::Vector2d(0.0, 0.0)));
  CHECK(cam.in_image(Eigen::Vector2d(751.0, 479.0)));
  CHECK_FALSE(cam.in_image(Eigen::Vector2d(751.5, 100.0)));
  CHECK_FALSE(cam.in_image(Eigen::Vector2d(-0.1, 100.0)));
  CHECK_FALSE(cam.in_image(Eigen::Vector2d(100.0, 479.5)));
  CHECK(cam.in_image(Eigen::Vector2d(10.0, 10.0), 10.0));
  CHECK_FALSE(cam.in_image(Eigen::Vector2d(9.9, 10.0), 10.0));
  CHECK_FALSE(cam.in_image(Eigen::Vector2d(741.1, 10.0), 10.0));
  CHECK_FALSE(cam.in_image(Eigen::Vector2d(std::nan(""), 10.0)));
}

TEST_CASE("camera_from_config inverts the camera-to-body T_BS") {
  const Config cfg = default_config();
  for (int i = 0; i < 2; ++i) {
    const std::string key = "cameras.cam" + std::to_string(i);
    const Eigen::Matrix4d T_BS = cfg.get_matrix(key + ".T_BS", 4, 4);
    const CameraCalibration c = camera_from_config(cfg.sub(key));
    std::mt19937 rng(6);
    std::normal_distribution<double> n(0.0, 2.0);
    for (int k = 0; k < 20; ++k) {
      const Eigen::Vector4d p_C(n(rng), n(rng), n(rng), 1.0);
      const Eigen::Vector3d p_I = (T_BS * p_C).head<3>();  // T_BS maps camera points into the IMU frame
      // Not exact: the file's R_BS is orthonormal only to ~1e-12, so R_BS^T
      // and R_BS^-1 differ at that level.
      CHECK((c.R_ItoC * p_I + c.p_IinC - p_C.head<3>()).norm() < 1e-10);
    }
  }
}

TEST_CASE("EuRoC stereo baseline is about 11 cm with cam0 left of cam1") {
  const Config cfg = default_config();
  // Reference from the raw numbers: T_C1<-C0 = T_BS1^-1 T_BS0 (general 4x4 inverse).
  const Eigen::Matrix4d T_BS0 = cfg.get_matrix("cameras.cam0.T_BS", 4, 4);
  const Eigen::Matrix4d T_BS1 = cfg.get_matrix("cameras.cam1.T_BS", 4, 4);
  const Eigen::Matrix4d T_C1C0 = T_BS1.inverse() * T_BS0;
  const Eigen::Vector3d p_C0inC1_ref = T_C1C0.topRightCorner<3, 1>();
  CHECK(std::abs(p_C0inC1_ref.norm() - 0.110) < 0.001);  // EuRoC: about 11.0 cm
  CHECK(p_C0inC1_ref.x() < -0.10);                       // left camera at -x of the right one

  // The same from the loaded extrinsics: p_C0inI = -R_ItoC0^T p_IinC0.
  const CameraCalibration c0 = default_cam(0), c1 = default_cam(1);
  const Eigen::Vector3d p_C0inI = -c0.R_ItoC.transpose() * c0.p_IinC;
  const Eigen::Vector3d p_C0inC1 = c1.R_ItoC * p_C0inI + c1.p_IinC;
  CHECK((p_C0inC1 - p_C0inC1_ref).norm() < 1e-12);
  const Eigen::Matrix3d R_C0toC1 = c1.R_ItoC * c0.R_ItoC.transpose();
  CHECK((R_C0toC1 - T_C1C0.topLeftCorner<3, 3>()).norm() < 1e-9);
}

TEST_CASE("config/euroc_stereo.yaml equals the EuRoC dataset calibration", "[data]") {
  const std::string mav0 = euroc_mav0("comparing config/euroc_stereo.yaml with the EuRoC files");
  if (mav0.empty()) return;
  const std::vector<CameraCalibration> dataset = load_euroc_cameras(mav0);
  REQUIRE(dataset.size() == 2);
  for (int i = 0; i < 2; ++i) {
    INFO("cam" << i);
    const CameraCalibration ours = default_cam(i);
    const CameraCalibration& ref = dataset[static_cast<std::size_t>(i)];
    // Same decimal digits parse to the same doubles: exact equality.
    CHECK(ours.width == ref.width);
    CHECK(ours.height == ref.height);
    CHECK(ours.intrinsics == ref.intrinsics);
    CHECK(ours.distortion == ref.distortion);
    CHECK(ours.R_ItoC == ref.R_ItoC);
    CHECK(ours.p_IinC == ref.p_IinC);
  }
  const Config imu_ours = default_config().sub("imu");
  const Config imu_ref = Config::load_file(mav0 + "/imu0/sensor.yaml");
  for (const char* key : {"gyroscope_noise_density", "gyroscope_random_walk", "accelerometer_noise_density",
                          "accelerometer_random_walk", "rate_hz"}) {
    INFO(key);
    CHECK(imu_ours.get<double>(key) == imu_ref.get<double>(key));
  }
  // Body = IMU frame holds only if imu0 sits at the body origin.
  CHECK(imu_ref.get_matrix("T_BS", 4, 4) == Eigen::Matrix4d::Identity());
}

TEST_CASE("load_euroc_cameras reads the EuRoC files", "[data]") {
  const std::string mav0 = euroc_mav0("loading the EuRoC camera files");
  if (mav0.empty()) return;
  const std::vector<CameraCalibration> cams = load_euroc_cameras(mav0);
  REQUIRE(cams.size() == 2);
  CHECK(cams[0].width == 752);
  CHECK(cams[0].height == 480);
  CHECK(cams[0].intrinsics(0) == 458.654);
  CHECK(cams[1].distortion(3) == -3.55590700e-05);
  for (const CameraCalibration& c : cams) CHECK_NOTHROW(CameraModel(c));
}

TEST_CASE("load_euroc_cameras throws ConfigError naming a missing cam0") {
  const std::string msg = message_of<ConfigError>([] { load_euroc_cameras("/nonexistent/mav0"); });
  CHECK_THAT(msg, Catch::Contains("/nonexistent/mav0/cam0/sensor.yaml"));
}

TEST_CASE("bad calibrations throw invalid_argument naming the bad value") {
  const CameraCalibration good = default_cam(0);
  REQUIRE_NOTHROW(CameraModel(good));
  auto msg = [](CameraCalibration c) {
    return message_of<std::invalid_argument>([&] { CameraModel model(c); });
  };
  CameraCalibration c = good;
  c.width = 0;
  CHECK_THAT(msg(c), Catch::Contains("width 0"));
  c = good;
  c.height = -480;
  CHECK_THAT(msg(c), Catch::Contains("height -480"));
  c = good;
  c.intrinsics(1) = -457.0;
  CHECK_THAT(msg(c), Catch::Contains("fy") && Catch::Contains("-457"));
  c = good;
  c.intrinsics(0) = 0.0;
  CHECK_THAT(msg(c), Catch::Contains("fx"));
  c = good;
  c.intrinsics(2) = std::numeric_limits<double>::infinity();
  CHECK_THAT(msg(c), Catch::Contains("cx") && Catch::Contains("inf"));
  c = good;
  c.distortion(1) = std::nan("");
  CHECK_THAT(msg(c), Catch::Contains("k2") && Catch::Contains("nan"));
  c = good;
  c.p_IinC(2) = std::nan("");
  CHECK_THAT(msg(c), Catch::Contains("p_IinC"));
  c = good;
  c.R_ItoC *= 1.01;  // scaled: not orthonormal
  CHECK_THAT(msg(c), Catch::Contains("R_ItoC"));
  c = good;
  c.R_ItoC.col(0) *= -1.0;  // orthonormal but a reflection
  CHECK_THAT(msg(c), Catch::Contains("R_ItoC") && Catch::Contains("det = -0.99999"));
}

TEST_CASE("camera_from_config reads the ASL layout and rejects what it cannot model") {
  const CameraCalibration c = camera_from_config(Config::from_string(kAslCamera, "asl.yaml"));
  CHECK(c.width == 752);
  CHECK(c.height == 480);
  CHECK(c.p_IinC.isApprox(Eigen::Vector3d(-0.1, 0.0, 0.0)));

  CHECK(c.distortion_model == DistortionModel::kRadialTangential);

  SECTION("the equidistant model with its four coefficients") {
    const std::string text = replace(kAslCamera, "radial-tangential", "equidistant");
    const CameraCalibration e = camera_from_config(Config::from_string(text, "asl.yaml"));
    CHECK(e.distortion_model == DistortionModel::kEquidistant);
    CHECK(e.distortion(3) == 1.76187114e-05);
  }
  SECTION("another distortion model") {
    const std::string text = replace(kAslCamera, "radial-tangential", "fov");
    const std::string msg = message_of<ConfigError>([&] { camera_from_config(Config::from_string(text, "asl.yaml")); });
    CHECK_THAT(msg, Catch::Contains("fov") && Catch::Contains("distortion_model") && Catch::Contains("asl.yaml"));
  }
  SECTION("another projection model") {
    const std::string text = replace(kAslCamera, "pinhole", "omni");
    const std::string msg = message_of<ConfigError>([&] { camera_from_config(Config::from_string(text, "asl.yaml")); });
    CHECK_THAT(msg, Catch::Contains("omni") && Catch::Contains("camera_model"));
  }
  SECTION("a missing key, named with its full path") {
    const std::string text = replace(kAslCamera, "intrinsics:", "intrinsic:");
    std::string nested = "cameras:\n  cam0:\n";
    std::istringstream lines(text.substr(text.find('\n') + 1));
    for (std::string line; std::getline(lines, line);) nested += "    " + line + "\n";
    const Config cfg = Config::from_string(nested, "rig.yaml");
    const std::string msg = message_of<ConfigError>([&] { camera_from_config(cfg.sub("cameras.cam0")); });
    CHECK_THAT(msg, Catch::Contains("cameras.cam0.intrinsics") && Catch::Contains("rig.yaml"));
  }
  SECTION("a distortion vector of the wrong length") {
    const std::string text = replace(kAslCamera, "1.76187114e-05]", "1.76187114e-05, 0.0]");
    const std::string msg = message_of<ConfigError>([&] { camera_from_config(Config::from_string(text, "asl.yaml")); });
    CHECK_THAT(msg, Catch::Contains("distortion_coefficients"));
  }
  SECTION("a bad value is a ConfigError naming the file") {
    const std::string text = replace(kAslCamera, "[458.654,", "[-458.654,");
    const std::string msg = message_of<ConfigError>([&] { camera_from_config(Config::from_string(text, "asl.yaml")); });
    CHECK_THAT(msg, Catch::Contains("asl.yaml") && Catch::Contains("fx") && Catch::Contains("-458.654"));
  }
  SECTION("a non-rigid T_BS") {
    const std::string text = replace(kAslCamera, "0.0, 0.0, 0.0, 1.0]", "0.0, 0.0, 0.5, 1.0]");
    const std::string msg = message_of<ConfigError>([&] { camera_from_config(Config::from_string(text, "asl.yaml")); });
    CHECK_THAT(msg, Catch::Contains("T_BS"));
  }
}

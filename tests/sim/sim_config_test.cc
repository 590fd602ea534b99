// SimConfig from the shipped YAML files, and refusal of bad values with the
// file, the full key and the offending value in the message.
#include <catch2/catch.hpp>

#include <cstdlib>

#include "common/config/config.h"
#include "common/sim/simulator.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

// A config text in the source's config/ directory (so calibration_file resolves).
std::string error_of(const std::string& yaml) {
  try {
    from_config(Config::from_string(yaml, test::source_path("config/inline_test.yaml")));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

const char* kMinimal = "scenario: paper\ncalibration_file: euroc_stereo.yaml\n";

}  // namespace

TEST_CASE("config/sim_paper.yaml: EuRoC stereo, 200 Hz IMU, 10 Hz cameras, 1 px, the paper geometry") {
  const SimConfig c = test::paper_config();
  CHECK(c.scenario == Scenario::kPaper);
  REQUIRE(c.camera.calibrations.size() == 2);
  CHECK(c.camera.calibrations[0].width == 752);
  CHECK(c.camera.calibrations[1].intrinsics(0) == Approx(457.587));
  CHECK(c.imu.rate_hz == 200.0);
  CHECK(c.camera.rate_hz == 10.0);
  CHECK(c.camera.pixel_noise == 1.0);
  CHECK(c.imu.gyroscope_noise_density == Approx(1.6968e-04));
  CHECK(c.imu.gyroscope_random_walk == Approx(1.9393e-05));
  CHECK(c.imu.accelerometer_noise_density == Approx(2.0e-3));
  CHECK(c.imu.accelerometer_random_walk == Approx(3.0e-3));
  CHECK(c.target.size == Eigen::Vector3d(1, 1, 1));
  CHECK(c.paper.radius == 50.0);
  CHECK_NOTHROW(validate(c));
}

TEST_CASE("config/sim_mono.yaml: one camera, a box, the free camera motion") {
  const SimConfig c = test::load_config("config/sim_mono.yaml");
  CHECK(c.scenario == Scenario::kMono);
  CHECK(c.camera.calibrations.size() == 1);
  CHECK(c.target.size == Eigen::Vector3d(0.4, 0.3, 0.3));
  CHECK(c.mono.camera_translation.size() == 2);
  CHECK(c.mono.camera_translation[1].frequency_hz == Eigen::Vector3d(1.31, 1.07, 1.73));
  CHECK(c.mono.anchor == CameraAnchor::kWorld);
  CHECK(c.mono.pointing == CameraPointing::kLookAtObject);
  CHECK(c.mono.object_heading == ObjectHeading::kAlongVelocity);
}

TEST_CASE("config/sim_trajectory.yaml: 400 Hz, 250 features per camera at 5-7 m, path from VIMOT_DATA_DIR") {
  const char* saved = std::getenv("VIMOT_DATA_DIR");
  const std::string saved_value = saved ? saved : "";
  setenv("VIMOT_DATA_DIR", "/some/data", 1);
  const SimConfig c = test::load_config("config/sim_trajectory.yaml");
  CHECK(c.trajectory.file == "/some/data/sim_trajectories/tum_corridor1_512_16_okvis.txt");
  CHECK(c.imu.rate_hz == 400.0);
  CHECK(c.camera.keep_per_camera == 250);
  CHECK(c.camera.spawn_depth_min == 5.0);
  CHECK(c.camera.spawn_depth_max == 7.0);
  CHECK(c.camera.calibrations.size() == 2);
  CHECK_FALSE(c.target.enabled);
  unsetenv("VIMOT_DATA_DIR");
  try {
    test::load_config("config/sim_trajectory.yaml");
    FAIL("no error without VIMOT_DATA_DIR");
  } catch (const ConfigError& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("trajectory.file") && Catch::Contains("VIMOT_DATA_DIR"));
  }
  if (saved) setenv("VIMOT_DATA_DIR", saved_value.c_str(), 1);
}

TEST_CASE("Invalid or unknown keys are refused naming the file, the key and the value") {
  CHECK(error_of(kMinimal).empty());
  std::string e = error_of(std::string(kMinimal) + "imu: {rate_hz: -5}\n");
  CHECK_THAT(e, Catch::Contains("inline_test.yaml") && Catch::Contains("imu.rate_hz") && Catch::Contains("-5"));
  e = error_of(std::string(kMinimal) + "camera: {rate_hz: 0}\n");
  CHECK_THAT(e, Catch::Contains("camera.rate_hz") && Catch::Contains("got 0"));
  e = error_of(std::string(kMinimal) + "camera: {track_loss_probability: 1.5}\n");
  CHECK_THAT(e, Catch::Contains("camera.track_loss_probability") && Catch::Contains("1.5"));
  e = error_of(std::string(kMinimal) + "camera: {pixel_noise: abc}\n");
  CHECK_THAT(e, Catch::Contains("camera.pixel_noise") && Catch::Contains("number"));
  e = error_of(std::string(kMinimal) + "camera: {mode: triple}\n");
  CHECK_THAT(e, Catch::Contains("camera.mode") && Catch::Contains("triple"));
  e = error_of(std::string(kMinimal) + "imu: {rate: 200}\n");
  CHECK_THAT(e, Catch::Contains("imu.rate") && Catch::Contains("unknown"));
  e = error_of(std::string(kMinimal) + "paper: {radius: -3}\n");
  CHECK_THAT(e, Catch::Contains("paper.radius") && Catch::Contains("-3"));
  e = error_of(std::string(kMinimal) + "paper: {oscillation: {amplitude: [1, 2]}}\n");
  CHECK_THAT(e, Catch::Contains("paper.oscillation.amplitude"));
  e = error_of("scenario: spiral\ncalibration_file: euroc_stereo.yaml\n");
  CHECK_THAT(e, Catch::Contains("scenario") && Catch::Contains("spiral"));
  e = error_of("calibration_file: euroc_stereo.yaml\n");
  CHECK_THAT(e, Catch::Contains("'scenario'") && Catch::Contains("missing"));
  e = error_of("scenario: paper\ncalibration_file: no_such_calibration.yaml\n");
  CHECK_THAT(e, Catch::Contains("no_such_calibration.yaml"));
  // Without a calibration file the cameras must be in the config itself.
  e = error_of("scenario: paper\n");
  CHECK_THAT(e, Catch::Contains("cameras.cam0"));
  e = error_of(std::string(kMinimal) + "mono: {camera_anchor: ceiling}\n");
  CHECK_THAT(e, Catch::Contains("mono.camera_anchor") && Catch::Contains("ceiling"));
  e = error_of(std::string(kMinimal) + "mono: {object_heading: north}\n");
  CHECK_THAT(e, Catch::Contains("mono.object_heading") && Catch::Contains("north"));
}

TEST_CASE("validate() and the Simulator refuse a bad SimConfig naming the field and value") {
  SimConfig c = test::paper_config();
  c.imu.rate_hz = -200.0;
  try {
    Simulator sim(c);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    CHECK_THAT(std::string(e.what()), Catch::Contains("imu.rate_hz") && Catch::Contains("-200"));
  }
  c = test::paper_config();
  c.camera.calibrations.clear();
  CHECK_THROWS_AS(validate(c), std::invalid_argument);
  c = test::paper_config();
  c.target.size = Eigen::Vector3d(0.05, 1, 1);
  CHECK_THROWS_WITH(validate(c), Catch::Contains("target.size"));
  c = test::paper_config();
  c.scenario = Scenario::kTrajectory;
  c.trajectory.file = "";
  CHECK_THROWS_WITH(validate(c), Catch::Contains("trajectory.file"));
}

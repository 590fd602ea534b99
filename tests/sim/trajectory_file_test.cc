// TUM trajectory reading: values and quaternion convention checked against
// Eigen's Hamilton quaternion, every malformed input refused with the line
// number, and the shared corridor file driving a full simulator run.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <string>
#include <unistd.h>

#include "common/sim/simulator.h"
#include "common/sim/trajectory_file.h"
#include "tests/data_dir.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

// A file in the temp directory, removed when the test ends.
class TempFile {
 public:
  explicit TempFile(const std::string& text) {
    char name[] = "/tmp/vimot_sim_traj_XXXXXX";
    const int fd = mkstemp(name);
    REQUIRE(fd >= 0);
    close(fd);
    path_ = name;
    std::ofstream(path_) << text;
  }
  ~TempFile() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string error_of(const std::string& text) {
  try {
    parse_tum_trajectory(text, "test.txt");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("A TUM file is read with times relative to the first pose and body-to-world Hamilton quaternions") {
  // Rotation of 90° about z as a Hamilton quaternion (x y z w).
  const double s = std::sqrt(0.5);
  const TempFile file(
      "# t x y z qx qy qz qw\n"
      "\n"
      "1520531829.500000 1.0 2.0 3.0 0 0 " + std::to_string(s) + " " + std::to_string(s) + "\n"
      "1520531829.550000 1.1 2.0 3.0 0 0 0 1   # trailing comment\n"
      "1520531829.600001 1.2 2.0 3.0 0 0 0 1\n");
  const PoseTrajectory traj = load_tum_trajectory(file.path());
  REQUIRE(traj.poses.size() == 3);
  CHECK(traj.t_first == Approx(1520531829.5));
  CHECK(traj.poses[0].t == 0.0);
  CHECK(traj.poses[1].t == Approx(0.05).margin(1e-9));
  CHECK(traj.poses[2].t == Approx(0.100001).margin(1e-9));  // µs resolution kept
  CHECK((traj.poses[0].p_BinG - Eigen::Vector3d(1, 2, 3)).norm() < 1e-12);
  // Body-to-world: the body x axis maps to world +y.
  const Eigen::Matrix3d R_expected = Eigen::Quaterniond(s, 0, 0, s).toRotationMatrix();
  CHECK((traj.poses[0].R_BtoG - R_expected).norm() < 1e-6);
  CHECK((traj.poses[0].R_BtoG * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm() < 1e-6);
}

TEST_CASE("Malformed trajectory files are refused with the file and line number") {
  const std::string good = "0.0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 1\n";
  CHECK(error_of(good).empty());
  std::string e = error_of(good + "# ok\n0.2 0 0 0 0 0 1\n");
  CHECK_THAT(e, Catch::Contains("test.txt") && Catch::Contains("line 4") && Catch::Contains("got 7"));
  e = error_of(good + "0.2 0 0 zero 0 0 0 1\n");
  CHECK_THAT(e, Catch::Contains("line 3") && Catch::Contains("'zero'"));
  e = error_of(good + "0.2 0 0 0 0 0 0 1 9\n");
  CHECK_THAT(e, Catch::Contains("line 3"));
  e = error_of(good + "0.1 0 0 0 0 0 0 1\n");
  CHECK_THAT(e, Catch::Contains("line 3") && Catch::Contains("does not increase") && Catch::Contains("line 2"));
  e = error_of(good + "0.05 0 0 0 0 0 0 1\n");
  CHECK_THAT(e, Catch::Contains("line 3") && Catch::Contains("does not increase"));
  e = error_of(good + "0.2 0 0 0 0 0 0 2\n");
  CHECK_THAT(e, Catch::Contains("line 3") && Catch::Contains("norm"));
  e = error_of(good + "0.2 0 0 0 0 0 0 nan\n");
  CHECK_THAT(e, Catch::Contains("line 3"));
  e = error_of("# only a comment\n0.0 0 0 0 0 0 0 1\n");
  CHECK_THAT(e, Catch::Contains("at least 2 poses"));
  try {
    load_tum_trajectory("/nonexistent/vimot/traj.txt");
    FAIL("no exception for a missing file");
  } catch (const std::runtime_error& err) {
    CHECK_THAT(std::string(err.what()), Catch::Contains("/nonexistent/vimot/traj.txt") &&
                                            Catch::Contains("cannot open"));
  }
}

TEST_CASE("A trajectory scenario from a file written here follows the file's poses") {
  // A circle of radius 2 m at 0.5 rad/s, body yawing with the motion, 20 Hz.
  std::string text = "# circle\n";
  for (int k = 0; k <= 400; ++k) {
    const double t = 100.0 + 0.05 * k, th = 0.5 * (t - 100.0);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(th + M_PI / 2, Eigen::Vector3d::UnitZ()));
    char line[256];
    std::snprintf(line, sizeof line, "%.6f %.9f %.9f 1.0 %.9f %.9f %.9f %.9f\n", t, 2 * std::cos(th),
                  2 * std::sin(th), q.x(), q.y(), q.z(), q.w());
    text += line;
  }
  const TempFile file(text);
  SimConfig c = test::paper_config();
  c.scenario = Scenario::kTrajectory;
  c.trajectory.file = file.path();
  c.target.enabled = false;
  c.map.floor_points = 0;
  c.map.wall_points = 0;
  c.camera.keep_per_camera = 50;
  c.camera.track_loss_probability = 0.0;
  c.camera.max_depth = 7.0;
  Simulator sim(c);
  // The OpenVINS rule: spline dt = max(mean spacing, 0.05) = 0.05 s; control
  // poses at 0, 0.05, ..., 20 s; valid from the second to the last but one.
  CHECK(sim.duration() == Approx(20.0 - 2 * 0.05).margin(1e-6));
  CHECK(sim.spline_time_offset() == Approx(0.05).margin(1e-9));
  CHECK(sim.path_length() == Approx(2.0 * 0.5 * sim.duration()).epsilon(0.002));
  for (double t = 0.0; t < sim.duration(); t += 0.77) {
    const double tf = t + 0.05, th = 0.5 * tf;  // file time since its first pose
    const SplineState s = sim.robot_state(t);
    // The cubic B-spline smooths the circle slightly: radius error ~ (ω dt)²/6 r.
    CHECK((s.p_BinG - Eigen::Vector3d(2 * std::cos(th), 2 * std::sin(th), 1.0)).norm() < 1e-3);
    CHECK((s.w_BinB - Eigen::Vector3d(0, 0, 0.5)).norm() < 1e-3);
  }
  // Keep-N: every camera frame reports the N static features per camera.
  int frames = 0;
  sim.run([&](const SimEvent& e) {
    if (const auto* f = std::get_if<CameraFrame>(&e)) {
      int n0 = 0, n1 = 0;
      for (const auto& o : f->observations) (o.camera_id == 0 ? n0 : n1)++;
      CHECK(n0 == 50);
      CHECK(n1 == 50);
      ++frames;
    }
  });
  CHECK(frames == sim.camera_frame_count());
}

TEST_CASE("The shared corridor trajectory drives the simulator (needs VIMOT_DATA_DIR)", "[data]") {
  const std::string path =
      vimot::test_data_file_or_skip("sim_trajectories/tum_corridor1_512_16_okvis.txt", "the shared trajectory file test");
  if (path.empty()) return;
  const PoseTrajectory traj = load_tum_trajectory(path);
  CHECK(traj.poses.size() == 5986);
  CHECK(traj.poses.back().t == Approx(299.26).margin(0.01));

  SimConfig c = test::load_config("config/sim_trajectory.yaml");
  CHECK(c.trajectory.file == path);
  c.duration = 20.0;
  Simulator sim(c);
  CHECK(sim.imu_sample_count() == 8001);  // 400 Hz
  CHECK(sim.camera_frame_count() == 201);
  // The spline passes close to the file's poses (it smooths ~5 cm steps).
  for (std::size_t k = 10; k < 300; k += 37) {
    const double t = traj.poses[k].t - sim.spline_time_offset();
    if (t < 0.0) continue;
    CHECK((sim.robot_state(t).p_BinG - traj.poses[k].p_BinG).norm() < 0.02);
  }
  int frames = 0;
  sim.run([&](const SimEvent& e) {
    if (const auto* f = std::get_if<CameraFrame>(&e)) {
      int n[2] = {0, 0};
      for (const auto& o : f->observations) n[o.camera_id]++;
      CHECK(n[0] == 250);
      CHECK(n[1] == 250);
      ++frames;
    }
  });
  CHECK(frames == 201);
}

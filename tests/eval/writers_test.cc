// TUM, CSV and JSON outputs: TUM round trip through the simulator's TUM
// reader, exact µs time stamps, the CSV columns, JSON write/read.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "common/eval/json.h"
#include "common/eval/writers.h"
#include "common/math/quat.h"
#include "common/sim/trajectory_file.h"

using namespace vimot;
using namespace vimot::eval;
using Catch::Matchers::WithinAbs;

namespace {

std::string temp_path(const char* stem) {
  char name[64];
  std::snprintf(name, sizeof(name), "/tmp/vimot_eval_%s_XXXXXX", stem);
  const int fd = mkstemp(name);
  REQUIRE(fd >= 0);
  close(fd);
  return name;
}

std::string read_all(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

}  // namespace

TEST_CASE("utime to seconds keeps every microsecond", "[eval][writers]") {
  CHECK(utime_to_seconds_string(0) == "0.000000");
  CHECK(utime_to_seconds_string(5) == "0.000005");
  CHECK(utime_to_seconds_string(1234567) == "1.234567");
  CHECK(utime_to_seconds_string(1520531829301144) == "1520531829.301144");
  CHECK(utime_to_seconds_string(-1500000) == "-1.500000");
  CHECK(utime_to_seconds_string(-1) == "-0.000001");
}

TEST_CASE("TUM writer round trip through parse_tum_trajectory", "[eval][writers]") {
  std::vector<StampedPose> poses;
  for (int k = 0; k < 5; ++k) {
    StampedPose p;
    p.utime = 1520531829000000 + 100000 * k + 7;  // epoch stamps, µs
    p.q_GtoI = rot_to_quat(exp_so3(Eigen::Vector3d(0.3 * k, -0.2, 0.1 + 0.5 * k)));
    p.p_IinG = Eigen::Vector3d(1.0 + k, -2.5 * k, 0.123456789);
    poses.push_back(p);
  }
  const std::string path = temp_path("tum");
  write_tum(path, poses, "two comment\nlines");
  const std::string text = read_all(path);
  CHECK(text.rfind("# two comment\n# lines\n1520531829.000007 ", 0) == 0);

  const sim::PoseTrajectory t = sim::parse_tum_trajectory(text, path);
  REQUIRE(t.poses.size() == poses.size());
  CHECK_THAT(t.t_first, WithinAbs(1520531829.000007, 1e-6));
  for (std::size_t k = 0; k < poses.size(); ++k) {
    INFO("pose " << k);
    CHECK_THAT(t.poses[k].t, WithinAbs(0.1 * static_cast<double>(k), 1e-9));
    CHECK((t.poses[k].p_BinG - poses[k].p_IinG).norm() < 1e-9);
    // TUM carries R_ItoG; the reader gives R_BtoG = R_GtoIᵀ.
    CHECK((t.poses[k].R_BtoG - quat_to_rot(poses[k].q_GtoI).transpose()).norm() < 1e-11);
  }
  // The line itself: Hamilton body-to-world = JPL q_GtoI components.
  std::istringstream line(tum_line(poses[1]));
  std::string ts;
  double x, y, z, qx, qy, qz, qw;
  line >> ts >> x >> y >> z >> qx >> qy >> qz >> qw;
  CHECK(ts == "1520531829.100007");
  const Eigen::Vector4d h = jpl_GtoI_to_hamilton_ItoG(poses[1].q_GtoI);
  CHECK((Eigen::Vector4d(qx, qy, qz, qw) - h).norm() < 1e-11);
  std::remove(path.c_str());
  CHECK_THROWS_AS(write_tum("/nonexistent_dir/x.tum", poses), std::runtime_error);
}

TEST_CASE("Error CSV: columns, degrees, 3-sigma", "[eval][writers]") {
  ErrorSample e;
  e.utime = 2500000;
  e.err_p = Eigen::Vector3d(0.1, -0.2, 0.3);
  e.err_theta = Eigen::Vector3d(M_PI / 180.0, 0.0, -2.0 * M_PI / 180.0);
  e.sig3_p = Eigen::Vector3d(0.3, 0.3, 0.6);
  e.sig3_theta = Eigen::Vector3d(3.0, 3.0, 6.0) * M_PI / 180.0;
  e.nees_p = 2.5;
  e.nees_theta = 3.5;
  std::ostringstream out;
  write_errors_csv(out, {e});
  std::istringstream in(out.str());
  std::string header, row;
  std::getline(in, header);
  std::getline(in, row);
  CHECK(header == "t,err_px,err_py,err_pz,err_rx,err_ry,err_rz,sig3_px,sig3_py,sig3_pz,sig3_rx,sig3_ry,sig3_rz,"
                  "nees_p,nees_r");
  std::vector<std::string> cells;
  std::istringstream r(row);
  for (std::string c; std::getline(r, c, ',');) cells.push_back(c);
  REQUIRE(cells.size() == 15);
  CHECK(cells[0] == "2.500000");
  const double expected[] = {0, 0.1, -0.2, 0.3, 1.0, 0.0, -2.0, 0.3, 0.3, 0.6, 3.0, 3.0, 6.0, 2.5, 3.5};
  for (int i = 1; i < 15; ++i) {
    INFO("column " << i);
    CHECK_THAT(std::stod(cells[static_cast<std::size_t>(i)]), WithinAbs(expected[i], 1e-8));
  }
}

TEST_CASE("JSON writer and reader", "[eval][json]") {
  JsonWriter j;
  j.begin_object();
  j.field("name", "a \"quoted\"\nname");
  j.field("pi", M_PI).field("n", int64_t{-42}).field("big", uint64_t{18446744073709551615ull});
  j.field("yes", true).field("nan", std::nan(""));
  j.key("list").begin_array().value(1.5).value("x").begin_object().end_object().begin_array().end_array().end_array();
  ErrorSummary s;
  s.rmse_position_m = 0.123456789012345678;
  s.rmse_orientation_deg = 1.25;
  s.nees_position = 2.9;
  s.nees_orientation = 3.1;
  s.predicted_rmse_position_m = 0.2;
  s.predicted_rmse_orientation_deg = 1.5;
  s.count = 1048;
  j.key("summary");
  write_summary_json(j, s);
  j.end_object();
  const std::string text = j.str();

  const JsonValue v = JsonValue::parse(text);
  CHECK(v.at("name").string() == "a \"quoted\"\nname");
  CHECK(v.at("pi").number() == M_PI);  // 17 digits round-trip
  CHECK(v.at("n").number() == -42.0);
  CHECK(v.at("yes").boolean());
  CHECK(std::isnan(v.at("nan").number()));
  CHECK(v.at("list").size() == 4);
  CHECK(v.at("list").at(1).string() == "x");
  CHECK_FALSE(v.has("absent"));
  CHECK_THROWS_AS(v.at("absent"), std::runtime_error);

  const std::string path = temp_path("json");
  write_text_file(path, text);
  const ErrorSummary r = read_summary_json(path);
  CHECK(r.rmse_position_m == s.rmse_position_m);
  CHECK(r.rmse_orientation_deg == 1.25);
  CHECK(r.nees_position == 2.9);
  CHECK(r.nees_orientation == 3.1);
  CHECK(r.predicted_rmse_position_m == 0.2);
  CHECK(r.predicted_rmse_orientation_deg == 1.5);
  CHECK(r.count == 1048);
  CHECK_THROWS_WITH(read_summary_json(path, "other"), Catch::Contains("other"));
  std::remove(path.c_str());

  CHECK_THROWS_AS(JsonValue::parse("{\"a\": 1,}"), std::runtime_error);
  CHECK_THROWS_AS(JsonValue::parse("[1, 2"), std::runtime_error);
  CHECK_THROWS_AS(JsonValue::parse("{} x"), std::runtime_error);
  JsonWriter bad;
  bad.begin_object();
  CHECK_THROWS_AS(bad.value(1.0), std::logic_error);  // value without key
  CHECK_THROWS_AS(bad.str(), std::logic_error);       // unbalanced
}

// EurocPlayer on small ASL folders written here: a good one plays, and every
// kind of bad input (missing folder, file or image, malformed CSV row,
// truncated PNG, wrong image size) throws EurocError naming the file.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include "common/math/quat.h"
#include "drivers/euroc_player/euroc_player.h"

namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using vimot::euroc::EurocError;
using vimot::euroc::EurocPlayer;
using vimot::euroc::PlayerOptions;
using vimot::euroc::StereoFrame;

constexpr int kWidth = 16;
constexpr int kHeight = 12;

void write_file(const fs::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// dataset/mav0 with 3 stereo frames 50 ms apart, IMU at 200 Hz over them.
class TempDataset {
 public:
  TempDataset() {
    root_ = fs::temp_directory_path() / ("vimot_euroc_test_" + std::to_string(::getpid()) + "_" +
                                         std::to_string(counter_++));
    fs::remove_all(root_);
    for (const char* cam : {"cam0", "cam1"}) {
      fs::create_directories(mav0() / cam / "data");
      write_file(mav0() / cam / "sensor.yaml",
                 "%YAML:1.0\nsensor_type: camera\nresolution: [" + std::to_string(kWidth) + ", " +
                     std::to_string(kHeight) + "]\n");
      std::string csv = "#timestamp [ns],filename\r\n";  // Windows line ends are read too
      for (int i = 0; i < 3; ++i) {
        const std::string name = std::to_string(frame_ns(i)) + ".png";
        csv += std::to_string(frame_ns(i)) + "," + name + "\r\n";
        cv::Mat image(kHeight, kWidth, CV_8UC1, cv::Scalar(40 * i + (cam[3] == '1' ? 7 : 0)));
        REQUIRE(cv::imwrite((mav0() / cam / "data" / name).string(), image));
      }
      write_file(mav0() / cam / "data.csv", csv);
    }
    fs::create_directories(mav0() / "imu0");
    std::string imu = "#timestamp [ns],w_x,w_y,w_z,a_x,a_y,a_z\n";
    for (int k = 0; k <= 20; ++k) {
      imu += std::to_string(frame_ns(0) + 5000000LL * k) + ",0.01,0.02,0.03,0.1,0.2,9.8\n";
    }
    write_file(mav0() / "imu0" / "data.csv", imu);
  }
  ~TempDataset() { fs::remove_all(root_); }

  static int64_t frame_ns(int i) { return 1000000000000LL + 50000000LL * i; }
  fs::path root() const { return root_; }
  fs::path mav0() const { return root_ / "mav0"; }
  fs::path image(const std::string& cam, int i) const {
    return mav0() / cam / "data" / (std::to_string(frame_ns(i)) + ".png");
  }
  PlayerOptions options() const {
    PlayerOptions o;
    o.dataset = root_.string();
    return o;
  }

 private:
  fs::path root_;
  static inline int counter_ = 0;
};

std::string error_of(const PlayerOptions& options) {
  try {
    EurocPlayer player(options);
  } catch (const EurocError& e) {
    return e.what();
  }
  return "";
}

StereoFrame first_frame(EurocPlayer& player) {
  while (auto e = player.next()) {
    if (const auto* f = std::get_if<StereoFrame>(&*e)) return *f;
  }
  FAIL("no stereo frame");
  return {};
}

}  // namespace

TEST_CASE("a well-formed generated folder plays", "[euroc]") {
  TempDataset d;
  EurocPlayer player(d.options());
  CHECK(player.summary().stereo_pairs == 3);
  CHECK(player.summary().imu_samples == 21);
  CHECK(player.summary().width == kWidth);
  const vimot::euroc::StereoImages images = player.load_images(first_frame(player));
  CHECK(images.left.at<uint8_t>(0, 0) == 0);
  CHECK(images.right.at<uint8_t>(0, 0) == 7);
  // The mav0 folder itself is accepted too.
  PlayerOptions o = d.options();
  o.dataset = d.mav0().string();
  CHECK(EurocPlayer(o).summary().stereo_pairs == 3);
  CHECK(vimot::euroc::ns_to_utime(1499) == 1);
  CHECK(vimot::euroc::ns_to_utime(1500) == 2);
}

TEST_CASE("a missing folder or data.csv is named", "[euroc]") {
  TempDataset d;
  PlayerOptions o = d.options();
  o.dataset = (d.root() / "nope").string();
  CHECK_THAT(error_of(o), Contains("nope") && Contains("does not exist"));
  fs::create_directories(d.root() / "empty");
  o.dataset = (d.root() / "empty").string();
  CHECK_THAT(error_of(o), Contains("not an ASL dataset folder"));
  fs::remove_all(d.mav0() / "imu0");
  CHECK_THAT(error_of(d.options()), Contains("missing folder") && Contains("imu0"));
  TempDataset d2;
  fs::remove(d2.mav0() / "cam1" / "data.csv");
  CHECK_THAT(error_of(d2.options()), Contains("cannot open") && Contains("cam1/data.csv"));
}

TEST_CASE("a missing image listed in data.csv is named with its line", "[euroc]") {
  TempDataset d;
  fs::remove(d.image("cam1", 1));
  const std::string e = error_of(d.options());
  CHECK_THAT(e, Contains("cam1/data.csv:3") && Contains(d.image("cam1", 1).string()) && Contains("does not exist"));
}

TEST_CASE("frames listed by one camera only are skipped and counted, not an error", "[euroc]") {
  TempDataset d;
  std::ofstream(d.mav0() / "cam1" / "data.csv", std::ios::app) << "1000150000000,1000150000000.png\n";
  EurocPlayer player(d.options());
  CHECK(player.summary().stereo_pairs == 3);
  CHECK(player.summary().unpaired_right == 1);
  CHECK(player.summary().unpaired_left == 0);
}

TEST_CASE("a malformed CSV row gives file:line and the text", "[euroc]") {
  TempDataset d;
  SECTION("a word where a number belongs") {
    write_file(d.mav0() / "imu0" / "data.csv", "#h\n1000000000000,0,0,0,0,0,9.8\n1000005000000,0,zero,0,0,0,9.8\n");
    CHECK_THAT(error_of(d.options()),
               Contains("imu0/data.csv:3") && Contains("'zero'") && Contains("1000005000000,0,zero,0,0,0,9.8"));
  }
  SECTION("a missing field") {
    write_file(d.mav0() / "imu0" / "data.csv", "#h\n1000000000000,0,0,0,0,9.8\n");
    CHECK_THAT(error_of(d.options()), Contains("imu0/data.csv:2") && Contains("got 6 fields"));
  }
  SECTION("a bad timestamp") {
    std::ofstream(d.mav0() / "cam0" / "data.csv", std::ios::app) << "12a4,x.png\n";
    CHECK_THAT(error_of(d.options()), Contains("cam0/data.csv:5") && Contains("'12a4'"));
  }
  SECTION("a time going backwards") {
    std::ofstream(d.mav0() / "cam0" / "data.csv", std::ios::app) << "1000050000000,x.png\n";
    CHECK_THAT(error_of(d.options()), Contains("cam0/data.csv:5") && Contains("does not increase"));
  }
  SECTION("a non-finite value") {
    write_file(d.mav0() / "imu0" / "data.csv", "1000000000000,0,nan,0,0,0,9.8\n");
    CHECK_THAT(error_of(d.options()), Contains("imu0/data.csv:1") && Contains("not a finite number"));
  }
}

TEST_CASE("a truncated PNG is a clear error when the pair loads", "[euroc]") {
  TempDataset d;
  const fs::path path = d.image("cam0", 0);
  fs::resize_file(path, fs::file_size(path) / 2);
  EurocPlayer player(d.options());  // listing and presence are fine
  const StereoFrame frame = first_frame(player);
  try {
    player.load_images(frame);
    FAIL("a truncated PNG loaded");
  } catch (const EurocError& e) {
    CHECK_THAT(e.what(), Contains(path.string()) && Contains("cannot be decoded"));
  }
  // Not an image at all.
  write_file(path, "not a png");
  CHECK_THROWS_WITH(player.load_images(frame), Contains(path.string()));
}

TEST_CASE("an image of the wrong size or type against sensor.yaml is a clear error", "[euroc]") {
  TempDataset d;
  REQUIRE(cv::imwrite(d.image("cam1", 0).string(), cv::Mat(kHeight - 2, kWidth, CV_8UC1, cv::Scalar(1))));
  REQUIRE(cv::imwrite(d.image("cam0", 1).string(), cv::Mat(kHeight, kWidth, CV_8UC3, cv::Scalar(1, 2, 3))));
  EurocPlayer player(d.options());
  const StereoFrame f0 = first_frame(player);
  CHECK_THROWS_WITH(player.load_images(f0), Contains(d.image("cam1", 0).string()) && Contains("is 16x10") &&
                                                Contains("sensor.yaml says 16x12"));
  const StereoFrame f1 = first_frame(player);
  CHECK_THROWS_WITH(player.load_images(f1), Contains(d.image("cam0", 1).string()) && Contains("not 8-bit grey"));
}

TEST_CASE("a missing or malformed sensor.yaml resolution is an error", "[euroc]") {
  TempDataset d;
  fs::remove(d.mav0() / "cam0" / "sensor.yaml");
  CHECK_THAT(error_of(d.options()), Contains("cam0/sensor.yaml"));
  write_file(d.mav0() / "cam0" / "sensor.yaml", "resolution: [16.5, 12]\n");
  CHECK_THAT(error_of(d.options()), Contains("resolution"));
}

TEST_CASE("ground truth: EuRoC layout, pose-only rows, and errors", "[euroc]") {
  TempDataset d;
  const fs::path gt_dir = d.mav0() / "state_groundtruth_estimate0";
  fs::create_directories(gt_dir);
  // 8 fields: pose only; a 90° yaw: R_ItoG = Rz(90°), Hamilton w = x-free.
  const double c = std::sqrt(0.5);
  write_file(gt_dir / "data.csv", "#time,px,py,pz,qw,qx,qy,qz\n1000000000000,1,2,3," + std::to_string(c) +
                                      ",0,0," + std::to_string(c) + "\n");
  {
    EurocPlayer player(d.options());
    CHECK(player.summary().groundtruth_poses == 1);
    CHECK(player.summary().groundtruth_file == (gt_dir / "data.csv").string());
    std::optional<vimot::GroundTruth> gt;
    while (auto e = player.next()) {
      if (const auto* g = std::get_if<vimot::GroundTruth>(&*e)) gt = *g;
    }
    REQUIRE(gt.has_value());
    CHECK(gt->p_IinG == Eigen::Vector3d(1, 2, 3));
    CHECK(gt->v_IinG.isZero());
    CHECK(gt->bias_gyro.isZero());
    // R_GtoI maps G's x axis onto I's -y axis for a body yawed by +90°.
    CHECK((vimot::quat_to_rot(gt->q_GtoI) * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, -1, 0)).norm() < 1e-6);
  }
  write_file(gt_dir / "data.csv", "1000000000000,1,2,3,0.5,0,0,0\n");
  CHECK_THAT(error_of(d.options()), Contains("data.csv:1") && Contains("quaternion norm"));
  PlayerOptions o = d.options();
  o.groundtruth_file = (d.root() / "absent.csv").string();
  CHECK_THAT(error_of(o), Contains("absent.csv") && Contains("does not exist"));
}

TEST_CASE("bad span options are rejected", "[euroc]") {
  TempDataset d;
  PlayerOptions o = d.options();
  o.start_s = 10.0;
  CHECK_THAT(error_of(o), Contains("no stereo pair in the span"));
  o.start_s = -1.0;
  CHECK_THAT(error_of(o), Contains("start"));
}

// EurocPlayer on the real EuRoC V1_01_easy slice (VIMOT_DATA_DIR): counts,
// order, timestamps and values against the dataset's own CSV files, read
// here by an independent parser. Exits with ctest's skip code (77) when
// VIMOT_DATA_DIR is unset or has no slice.
#include "tests/drivers/euroc_player/slice_test_main.h"

#include <Eigen/Geometry>
#include <fstream>
#include <string>
#include <vector>

#include "common/math/quat.h"
#include "common/process/image_conversion.h"
#include "drivers/euroc_player/euroc_player.h"

namespace {

using vimot::euroc::EurocPlayer;
using vimot::euroc::PlayerEvent;
using vimot::euroc::PlayerOptions;
using vimot::euroc::StereoFrame;

// First column (ns) of every data row of an ASL CSV.
std::vector<long long> csv_times(const std::string& path) {
  std::ifstream in(path);
  REQUIRE(in.good());
  std::vector<long long> t;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    t.push_back(std::stoll(line.substr(0, line.find(','))));
  }
  return t;
}

int64_t utime_of(const PlayerEvent& e) {
  return std::visit([](const auto& x) { return x.utime; }, e);
}

std::vector<PlayerEvent> play_all(EurocPlayer& player) {
  std::vector<PlayerEvent> events;
  while (auto e = player.next()) events.push_back(*e);
  return events;
}

PlayerOptions slice_options() {
  PlayerOptions o;
  o.dataset = slice_dir();
  o.groundtruth_file = slice_dir() + "/groundtruth/V1_01_easy.csv";
  return o;
}

}  // namespace

TEST_CASE("the slice plays 95 stereo pairs, the IMU of their span and its ground truth", "[euroc][data]") {
  EurocPlayer player(slice_options());
  const auto& s = player.summary();
  CHECK(s.width == 752);
  CHECK(s.height == 480);
  CHECK(s.stereo_pairs == 95);
  // cam1/data.csv lists 4 frames past the last image; cam0 does not.
  CHECK(s.unpaired_left == 0);
  CHECK(s.unpaired_right == 4);
  // The IMU starts with the first frame (no lead data in the file): 4.7 s at
  // 200 Hz, both ends included.
  CHECK(s.imu_samples == 941);
  CHECK(s.groundtruth_poses == 95);

  const std::vector<PlayerEvent> events = play_all(player);
  REQUIRE(events.size() == 95u + 941u + 95u);
  int n_frames = 0, n_imu = 0, n_gt = 0;
  for (const auto& e : events) {
    n_frames += std::holds_alternative<StereoFrame>(e);
    n_imu += std::holds_alternative<vimot::ImuData>(e);
    n_gt += std::holds_alternative<vimot::GroundTruth>(e);
  }
  CHECK(n_frames == 95);
  CHECK(n_imu == 941);
  CHECK(n_gt == 95);
  CHECK_FALSE(player.next().has_value());
}

TEST_CASE("events are time ordered, IMU and truth before a frame of the same time", "[euroc][data]") {
  EurocPlayer player(slice_options());
  const std::vector<PlayerEvent> events = play_all(player);
  int frames_with_imu_at_same_time = 0;
  for (std::size_t i = 1; i < events.size(); ++i) {
    REQUIRE(utime_of(events[i - 1]) <= utime_of(events[i]));
    if (utime_of(events[i - 1]) == utime_of(events[i])) {
      // variant order ImuData < GroundTruth < StereoFrame
      REQUIRE(events[i - 1].index() < events[i].index());
    }
    if (std::holds_alternative<StereoFrame>(events[i])) {
      // Every frame of the slice has an IMU sample at its time (200 Hz on the
      // 20 Hz camera clock), played before it.
      for (std::size_t j = i; j-- > 0 && utime_of(events[j]) == utime_of(events[i]);) {
        if (std::holds_alternative<vimot::ImuData>(events[j])) {
          ++frames_with_imu_at_same_time;
          break;
        }
      }
    }
  }
  CHECK(frames_with_imu_at_same_time == 95);
}

TEST_CASE("timestamps and values are the CSV's", "[euroc][data]") {
  const std::vector<long long> cam0 = csv_times(slice_dir() + "/mav0/cam0/data.csv");
  const std::vector<long long> imu = csv_times(slice_dir() + "/mav0/imu0/data.csv");
  REQUIRE(cam0.size() == 95u);
  EurocPlayer player(slice_options());
  std::size_t frame = 0, sample = 0;
  bool first_imu = true;
  while (auto e = player.next()) {
    if (const auto* f = std::get_if<StereoFrame>(&*e)) {
      REQUIRE(frame < cam0.size());
      CHECK(f->timestamp_ns == cam0[frame]);
      CHECK(f->utime == (cam0[frame] + 500) / 1000);
      CHECK(f->left_path == slice_dir() + "/mav0/cam0/data/" + std::to_string(cam0[frame]) + ".png");
      CHECK(f->right_path == slice_dir() + "/mav0/cam1/data/" + std::to_string(cam0[frame]) + ".png");
      ++frame;
    } else if (const auto* m = std::get_if<vimot::ImuData>(&*e)) {
      CHECK(m->utime == (imu[sample] + 500) / 1000);
      if (first_imu) {
        // imu0/data.csv, first row.
        CHECK(m->w_IinI.x() == -0.0020943951023931952);
        CHECK(m->w_IinI.y() == 0.017453292519943295);
        CHECK(m->w_IinI.z() == 0.07749261878854824);
        CHECK(m->a_IinI.x() == 9.0874956666666655);
        CHECK(m->a_IinI.y() == 0.13075533333333333);
        CHECK(m->a_IinI.z() == -3.6938381666666662);
        first_imu = false;
      }
      ++sample;
    }
  }
  CHECK(frame == 95u);
  // Hand values: 1403715273262142976 ns -> 1403715273262143 µs (rounded).
  player.rewind();
  CHECK(player.first_utime() == 1403715273262143);
  CHECK(player.last_utime() == 1403715277962143);
}

TEST_CASE("the first ground-truth pose is the CSV's, quaternion in JPL", "[euroc][data]") {
  EurocPlayer player(slice_options());
  std::optional<vimot::GroundTruth> gt;
  while (auto e = player.next()) {
    if (const auto* g = std::get_if<vimot::GroundTruth>(&*e)) {
      gt = *g;
      break;
    }
  }
  REQUIRE(gt.has_value());
  // groundtruth/V1_01_easy.csv, first row:
  // 1403715273262142976,0.878895,2.1834,0.948427,0.069433,-0.824237,-0.106942,-0.551702,
  // 0.00157587,0.00179383,-0.00231615,-0.00224703,0.0215352,0.0770299,-0.0180115,0.0659796,0.0309774
  CHECK(gt->utime == 1403715273262143);
  CHECK(gt->p_IinG.isApprox(Eigen::Vector3d(0.878895, 2.1834, 0.948427), 1e-15));
  CHECK(gt->v_IinG.isApprox(Eigen::Vector3d(0.00157587, 0.00179383, -0.00231615), 1e-15));
  CHECK(gt->bias_gyro.isApprox(Eigen::Vector3d(-0.00224703, 0.0215352, 0.0770299), 1e-15));
  CHECK(gt->bias_accel.isApprox(Eigen::Vector3d(-0.0180115, 0.0659796, 0.0309774), 1e-15));
  // Hamilton (w, x, y, z) of R_ItoG; Eigen's Quaterniond is Hamilton, so
  // R_GtoI = R_ItoG^T is derived here without the converters under test.
  const Eigen::Quaterniond q_ItoG(0.069433, -0.824237, -0.106942, -0.551702);
  const Eigen::Matrix3d R_GtoI = q_ItoG.normalized().toRotationMatrix().transpose();
  CHECK((vimot::quat_to_rot(gt->q_GtoI) - R_GtoI).norm() < 1e-12);
  // By hand: JPL q_GtoI = [x y z w] of the Hamilton q_ItoG (w >= 0 already).
  const Eigen::Vector4d q_hand = Eigen::Vector4d(-0.824237, -0.106942, -0.551702, 0.069433).normalized();
  CHECK((gt->q_GtoI - q_hand).norm() < 1e-15);
}

TEST_CASE("without a ground-truth file the slice plays no truth (it has no state_groundtruth_estimate0/data.csv)",
          "[euroc][data]") {
  PlayerOptions o = slice_options();
  o.groundtruth_file.clear();
  EurocPlayer player(o);
  CHECK(player.summary().groundtruth_file.empty());
  CHECK(player.summary().groundtruth_poses == 0);
  o.groundtruth_file = slice_dir() + "/groundtruth/V1_01_easy.csv";
  o.use_groundtruth = false;
  CHECK(EurocPlayer(o).summary().groundtruth_poses == 0);
}

TEST_CASE("the span options select frames, and IMU from the lead before them", "[euroc][data]") {
  PlayerOptions o = slice_options();
  o.start_s = 1.0;
  o.duration_s = 0.975;
  o.imu_lead_s = 0.5;
  EurocPlayer player(o);
  // cam0/data.csv rows 21..40: 1403715274262142976 (t0 + 1.0 s exactly) to
  // 1403715275212143104 (t0 + 1.95 s); row 41 is past t0 + 1.975 s.
  CHECK(player.summary().stereo_pairs == 20);
  CHECK(player.summary().span_start_utime == 1403715274262143);
  CHECK(player.summary().span_end_utime == 1403715275212143);
  // IMU from 0.5 s before the first pair (samples every 5 ms on the same
  // clock), through the sample at the last pair.
  const auto first = player.next();
  REQUIRE(std::holds_alternative<vimot::ImuData>(*first));
  CHECK(utime_of(*first) == 1403715273762143);
  CHECK(player.summary().imu_samples == 100 + 190 + 1);
  CHECK(player.last_utime() == 1403715275212143);
}

TEST_CASE("images load lazily as 752x480 grey and convert to image_t byte for byte", "[euroc][data]") {
  EurocPlayer player(slice_options());
  std::optional<StereoFrame> frame;
  while (auto e = player.next()) {
    if (const auto* f = std::get_if<StereoFrame>(&*e)) {
      frame = *f;
      break;
    }
  }
  REQUIRE(frame.has_value());
  const vimot::euroc::StereoImages images = player.load_images(*frame);
  REQUIRE(images.left.type() == CV_8UC1);
  REQUIRE(images.right.type() == CV_8UC1);
  CHECK(images.left.cols == 752);
  CHECK(images.left.rows == 480);
  // Two cameras 11 cm apart do not give the same picture.
  CHECK(cv::norm(images.left, images.right, cv::NORM_L1) > 0.0);
  const vimot::image_t msg = vimot::to_lcm_image(images.left, frame->utime);
  CHECK(msg.utime == frame->utime);
  CHECK(msg.pixelformat == vimot::image_t::PIXEL_FORMAT_GRAY);
  CHECK(msg.row_stride == 752);
  CHECK(msg.size == 752 * 480);
  CHECK(msg.data[752 * 100 + 200] == images.left.at<uint8_t>(100, 200));
  CHECK(cv::norm(vimot::grey_from_lcm_image(msg), images.left, cv::NORM_INF) == 0.0);
}

// MaskFilterNode (procs/mask_filter) without LCM, with the shipped config
// (stereo, 752x480): one filter per camera, a box per valid mask, bad input
// counted and answered with no box, never a crash.
#include <catch2/catch.hpp>

#include <vector>

#include "common/config/config.h"
#include "procs/mask_filter/mask_filter_node.h"

using namespace vimot;
using Outcome = segmentation::BoxKalmanFilter::Outcome;

namespace {

constexpr int kW = 752, kH = 480;

// A 752x480 mask with the target rectangle [x, y, w, h] set (w = 0: empty).
std::vector<uint8_t> mask_with(int x, int y, int w, int h) {
  std::vector<uint8_t> m(static_cast<std::size_t>(kW * kH), 0);
  for (int r = y; r < y + h; ++r) {
    for (int c = x; c < x + w; ++c) m[static_cast<std::size_t>(r * kW + c)] = 1;
  }
  return m;
}

struct Run {
  Run()
      : node(MaskFilterNodeOptions::from_config(
                 Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/mask_filter.yaml")),
             [this](const CameraBox& b) { boxes.push_back(b); },
             [this](const NodeEvent& e) { events.push_back(e); }) {}
  std::vector<CameraBox> boxes;
  std::vector<NodeEvent> events;
  MaskFilterNode node;
};

}  // namespace

TEST_CASE("mask filter node: each camera's masks go through that camera's filter") {
  Run run;
  REQUIRE(run.node.num_cameras() == 2);
  const auto left = mask_with(100, 200, 60, 40), right = mask_with(300, 100, 50, 30);
  run.node.on_mask(0, 1000, kW, kH, kW * kH, left);
  run.node.on_mask(1, 1000, kW, kH, kW * kH, right);  // same utime, other camera: fine
  run.node.on_mask(0, 101000, kW, kH, kW * kH, left);
  REQUIRE(run.boxes.size() == 3);
  CHECK(run.boxes[0].camera_id == 0);
  CHECK(run.boxes[0].estimate.raw_box == Eigen::Vector4d(100, 200, 60, 40));
  CHECK(run.boxes[0].estimate.outcome == Outcome::kInitialised);
  CHECK(run.boxes[1].camera_id == 1);
  CHECK(run.boxes[1].estimate.raw_box == Eigen::Vector4d(300, 100, 50, 30));
  CHECK(run.boxes[1].estimate.filtered_box.isApprox(Eigen::Vector4d(300, 100, 50, 30)));
  CHECK(run.boxes[2].estimate.outcome == Outcome::kFused);
  CHECK(run.boxes[2].estimate.utime == 101000);
  CHECK(run.node.masks_processed() == 3);
  CHECK(run.node.detections() == 3);
  CHECK(run.node.errors() == 0);
}

TEST_CASE("mask filter node: bad masks are counted and produce no box; an empty mask is a frame without detection") {
  Run run;
  const auto target = mask_with(100, 200, 60, 40);
  run.node.on_mask(0, 1000, kW, kH, kW * kH, target);
  REQUIRE(run.boxes.size() == 1);

  run.node.on_mask(0, 2000, kW, kH, kW * kH - 1, target);  // size field disagrees with width·height
  run.node.on_mask(0, 3000, kW, kH + 1, kW * (kH + 1), target);  // size field right, bytes short
  const std::vector<uint8_t> small(640 * 480, 0);
  run.node.on_mask(0, 4000, 640, 480, 640 * 480, small);  // not the camera's resolution
  run.node.on_mask(2, 5000, kW, kH, kW * kH, target);     // no such camera
  run.node.on_mask(0, 6000, -1, kH, -kH, target);          // negative width
  CHECK(run.node.errors() == 5);
  CHECK(run.boxes.size() == 1);

  run.node.on_mask(0, 1000, kW, kH, kW * kH, target);  // time not advancing: dropped
  run.node.on_mask(0, 500, kW, kH, kW * kH, target);   // going backwards: dropped
  CHECK(run.node.masks_dropped() == 2);
  CHECK(run.boxes.size() == 1);
  int dropped_events = 0, error_events = 0;
  for (const NodeEvent& e : run.events) {
    dropped_events += e.kind == NodeEvent::Kind::kDropped;
    error_events += e.kind == NodeEvent::Kind::kError;
  }
  CHECK(dropped_events == 2);
  CHECK(error_events == 5);

  // An empty mask: the filter coasts and a box is still published.
  run.node.on_mask(0, 101000, kW, kH, kW * kH, mask_with(0, 0, 0, 0));
  REQUIRE(run.boxes.size() == 2);
  const segmentation::BoxEstimate& e = run.boxes.back().estimate;
  CHECK_FALSE(e.raw_valid);
  CHECK(e.filtered_valid);
  CHECK(e.frames_since_raw == 1);
  CHECK(e.outcome == Outcome::kCoasted);
  CHECK(run.node.no_detections() == 1);
  CHECK(run.node.masks_processed() == 2);

  // Still working after all that.
  run.node.on_mask(0, 201000, kW, kH, kW * kH, target);
  CHECK(run.boxes.back().estimate.outcome == Outcome::kFused);
}

TEST_CASE("mask filter node: no detection for longer than max_coast_s drops the box, counted once") {
  Run run;
  run.node.on_mask(1, 0, kW, kH, kW * kH, mask_with(10, 10, 30, 30));
  const auto empty = mask_with(0, 0, 0, 0);
  for (int k = 1; k <= 12; ++k) run.node.on_mask(1, k * 100000, kW, kH, kW * kH, empty);  // 1.2 s
  CHECK(run.node.tracks_dropped() == 1);
  CHECK_FALSE(run.boxes.back().estimate.filtered_valid);
  CHECK(run.boxes.size() == 13);
}

TEST_CASE("mask filter node: config errors name the key") {
  const auto err = [](const std::string& yaml) {
    try {
      MaskFilterNodeOptions::from_config(Config::from_string(yaml, "test.yaml"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("<no error>");
  };
  const std::string cams =
      "cameras: {cam0: {resolution: [752, 480], intrinsics: [458, 457, 367, 248], "
      "distortion_model: radial-tangential, distortion_coefficients: [0, 0, 0, 0], "
      "T_BS: {rows: 4, cols: 4, data: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}}\n";
  CHECK_THAT(err(cams + "mode: mono\nfilterr: {}\n"), Catch::Contains("filterr"));
  CHECK_THAT(err(cams + "mode: triple\n"), Catch::Contains("mode"));
  CHECK(err(cams + "mode: mono\n") == "<no error>");
}

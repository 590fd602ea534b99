// FeatureTrackerNode without a network: stereo pairing by utime, dropped
// unpaired and late images, wrong-size images as counted errors, target
// boxes by utime, mono.
#include "procs/feature_tracker/feature_tracker_node.h"

#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "tests/frontend/synthetic_images.h"

using namespace vimot;

namespace {

struct Recorder {
  std::vector<CameraFrame> frames;
  std::vector<NodeEvent> events;
  int count(NodeEvent::Kind kind) const {
    int n = 0;
    for (const NodeEvent& e : events) n += e.kind == kind ? 1 : 0;
    return n;
  }
};

FeatureTrackerNodeOptions options(int cameras) {
  FeatureTrackerNodeOptions o;
  const CameraCalibration cam = test::pinhole(320, 240, 250.0);
  o.cameras.assign(static_cast<std::size_t>(cameras), cam);
  return o;
}

FeatureTrackerNode make_node(const FeatureTrackerNodeOptions& o, Recorder& r) {
  return FeatureTrackerNode(
      o, [&r](const CameraFrame& f) { r.frames.push_back(f); }, [&r](const NodeEvent& e) { r.events.push_back(e); });
}

}  // namespace

TEST_CASE("the node pairs left and right by utime in either arrival order and drops the unpaired") {
  Recorder r;
  FeatureTrackerNode node = make_node(options(2), r);
  const cv::Mat image = test::make_texture(320, 240, 51, 400);
  node.on_image(0, 100, image);
  CHECK(r.frames.empty());
  node.on_image(1, 100, image);
  REQUIRE(r.frames.size() == 1);
  CHECK(r.frames[0].utime == 100);
  node.on_image(1, 200, image);  // right first
  node.on_image(0, 200, image);
  REQUIRE(r.frames.size() == 2);
  CHECK(r.frames[1].utime == 200);
  // A left image whose right never comes is dropped once a later pair completes.
  node.on_image(0, 300, image);
  node.on_image(0, 400, image);
  node.on_image(1, 400, image);
  REQUIRE(r.frames.size() == 3);
  CHECK(r.frames[2].utime == 400);
  CHECK(node.images_dropped() == 1);
  CHECK(r.count(NodeEvent::Kind::kDropped) == 1);
  // Late (not after the last tracked frame) and duplicate images are dropped.
  node.on_image(1, 350, image);
  node.on_image(0, 500, image);
  node.on_image(0, 500, image);
  CHECK(node.images_dropped() == 3);
  // Stereo observations carry one id in both cameras.
  bool both = false;
  for (const FeatureObservation& o : r.frames[2].observations) both = both || o.camera_id == 1;
  CHECK(both);
  CHECK(node.errors() == 0);
}

TEST_CASE("the node bounds the images waiting for a partner") {
  Recorder r;
  FeatureTrackerNodeOptions o = options(2);
  o.max_pending_images = 2;
  FeatureTrackerNode node = make_node(o, r);
  const cv::Mat image = test::make_texture(320, 240, 52, 400);
  for (int k = 1; k <= 5; ++k) node.on_image(0, k * 100, image);
  CHECK(node.images_dropped() == 3);
  node.on_image(1, 500, image);
  CHECK(r.frames.size() == 1);
  CHECK(node.images_dropped() == 4);  // 400 never found its partner
}

TEST_CASE("the node counts a wrong-size or non-grey image as an error and carries on") {
  Recorder r;
  FeatureTrackerNode node = make_node(options(2), r);
  const cv::Mat image = test::make_texture(320, 240, 53, 400);
  node.on_image(0, 100, test::make_texture(640, 480, 53, 400));
  CHECK(node.errors() == 1);
  REQUIRE(r.count(NodeEvent::Kind::kError) == 1);
  CHECK_THAT(r.events.back().message, Catch::Contains("640x480") && Catch::Contains("320x240"));
  cv::Mat colour;
  cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
  node.on_image(1, 100, colour);
  CHECK(node.errors() == 2);
  node.on_image(2, 100, image);
  CHECK(node.errors() == 3);
  node.on_image(0, 100, image);
  node.on_image(1, 100, image);
  CHECK(r.frames.size() == 1);
}

TEST_CASE("the node uses each camera's box at or before the frame, and mono tracks the left alone") {
  Recorder r;
  FeatureTrackerNode node = make_node(options(1), r);
  CHECK_FALSE(node.stereo());
  const cv::Mat image = test::make_texture(320, 240, 54, 400);
  node.on_image(0, 100, image);
  REQUIRE(r.frames.size() == 1);
  for (const FeatureObservation& o : r.frames[0].observations) CHECK_FALSE(o.is_target);
  const frontend::Box box{100.0, 60.0, 120.0, 100.0};
  node.on_box(0, 200, box);
  node.on_box(0, 400, frontend::Box{0.0, 0.0, 10.0, 10.0});  // for a later image: not used at 200
  node.on_image(0, 200, image);
  REQUIRE(r.frames.size() == 2);
  int targets = 0;
  for (const FeatureObservation& o : r.frames[1].observations) {
    CHECK(o.is_target == box.contains(o.pixel.x(), o.pixel.y()));
    targets += o.is_target ? 1 : 0;
  }
  CHECK(targets > 0);
  node.on_image(1, 300, image);
  CHECK(node.errors() == 1);  // a mono tracker has no right camera
  node.on_box(0, 250, frontend::Box{std::nan(""), 0.0, 1.0, 1.0});
  CHECK(node.errors() == 2);
}

TEST_CASE("with wait_for_box a frame waits for its boxes, or for the next frame when no box comes") {
  Recorder r;
  FeatureTrackerNodeOptions o = options(2);
  o.wait_for_box = true;
  FeatureTrackerNode node = make_node(o, r);
  const cv::Mat image = test::make_texture(320, 240, 55, 400);
  const frontend::Box box{100.0, 60.0, 120.0, 100.0};
  node.on_image(0, 1000000, image);
  node.on_image(1, 1000000, image);
  node.on_box(0, 1000000, box);
  CHECK(r.frames.empty());  // the right box is still missing
  node.on_box(1, 1000000, box);
  REQUIRE(r.frames.size() == 1);
  int targets[2] = {0, 0};
  for (const FeatureObservation& f : r.frames[0].observations) targets[f.camera_id] += f.is_target ? 1 : 0;
  CHECK(targets[0] > 0);
  CHECK(targets[1] > 0);
  // No boxes at 2 s (the 1 s box is older than box_max_age_s): that frame
  // goes out when the 3 s frame is complete, without a box.
  node.on_image(0, 2000000, image);
  node.on_image(1, 2000000, image);
  CHECK(r.frames.size() == 1);
  node.on_image(0, 3000000, image);
  node.on_image(1, 3000000, image);
  REQUIRE(r.frames.size() == 2);
  CHECK(r.frames[1].utime == 2000000);
  for (const FeatureObservation& f : r.frames[1].observations) CHECK_FALSE(f.is_target);
  node.flush();
  REQUIRE(r.frames.size() == 3);
  CHECK(r.frames[2].utime == 3000000);
  CHECK(node.errors() == 0);
}

TEST_CASE("with box_wait_frames a frame waits that many later frames for boxes that come late") {
  Recorder r;
  FeatureTrackerNodeOptions o = options(2);
  o.wait_for_box = true;
  o.box_wait_frames = 2;
  FeatureTrackerNode node = make_node(o, r);
  const cv::Mat image = test::make_texture(320, 240, 55, 400);
  const frontend::Box box{100.0, 60.0, 120.0, 100.0};
  for (int64_t t : {1000000, 2000000}) {
    node.on_image(0, t, image);
    node.on_image(1, t, image);
  }
  CHECK(r.frames.empty());  // one later frame is complete: the 1 s frame still waits (box_wait_frames 1 would not)
  node.on_box(0, 1000000, box);
  node.on_box(1, 1000000, box);
  REQUIRE(r.frames.size() == 1);  // its boxes came after the next frame's images and are used
  int targets = 0;
  for (const FeatureObservation& f : r.frames[0].observations) targets += f.is_target ? 1 : 0;
  CHECK(targets > 0);
  // The 2 s frame's boxes never come: it goes out once two later frames are complete.
  for (int64_t t : {3000000, 4000000}) {
    CHECK(r.frames.size() == 1);
    node.on_image(0, t, image);
    node.on_image(1, t, image);
  }
  REQUIRE(r.frames.size() == 2);
  CHECK(r.frames[1].utime == 2000000);
  for (const FeatureObservation& f : r.frames[1].observations) CHECK_FALSE(f.is_target);
  CHECK(node.errors() == 0);
}

TEST_CASE("with target.use_mask a frame waits for its mask too, and its target points lie on the eroded mask") {
  Recorder r;
  FeatureTrackerNodeOptions o = options(1);
  o.wait_for_box = true;
  o.tracker.target.use_mask = true;
  FeatureTrackerNode node = make_node(o, r);
  REQUIRE(node.uses_mask());
  const cv::Mat image = test::make_texture(320, 240, 55, 400);
  const frontend::Box box{100.0, 60.0, 120.0, 100.0};
  // The target: the box's left half (columns 100..159, rows 60..159).
  cv::Mat mask = cv::Mat::zeros(240, 320, CV_8UC1);
  mask(cv::Rect(100, 60, 60, 100)).setTo(255);
  node.on_image(0, 100, image);
  node.on_box(0, 100, box);
  CHECK(r.frames.empty());  // its mask has not come
  node.on_mask(0, 50, cv::Mat::zeros(240, 320, CV_8UC1));  // an earlier frame's: not this one's
  CHECK(r.frames.empty());
  node.on_mask(0, 100, mask);
  REQUIRE(r.frames.size() == 1);
  int targets = 0;
  for (const FeatureObservation& f : r.frames[0].observations) {
    if (!f.is_target) continue;
    ++targets;
    // The whole 15 px window (±7.5 px) on the mask's pixels (centres 100..159, 60..159).
    CHECK(f.pixel.x() - 7.5 >= 99.5);
    CHECK(f.pixel.x() + 7.5 <= 159.5);
    CHECK(f.pixel.y() - 7.5 >= 59.5);
    CHECK(f.pixel.y() + 7.5 <= 159.5);
  }
  CHECK(targets > 0);
  node.on_mask(0, 200, cv::Mat::zeros(10, 10, CV_8UC1));
  CHECK(node.errors() == 1);  // wrong size: taken as no mask, the frame not held for it
  node.on_box(0, 200, box);
  node.on_image(0, 200, image);
  CHECK(r.frames.size() == 2);
}

TEST_CASE("FeatureTrackerNodeOptions reads config/feature_tracker.yaml and refuses unknown keys") {
  const Config cfg = Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/feature_tracker.yaml");
  const FeatureTrackerNodeOptions o = FeatureTrackerNodeOptions::from_config(cfg);
  REQUIRE(o.cameras.size() == 2);
  CHECK(o.cameras[0].width == 752);
  CHECK(o.max_pending_images == 4);
  CHECK_FALSE(o.wait_for_box);
  const std::string text = "calibration_file: " + std::string(VIMOT_SOURCE_DIR) +
                           "/config/euroc_stereo.yaml\nmode: mono\nnode: {box_max_age: 1}\n";
  CHECK_THROWS_WITH(FeatureTrackerNodeOptions::from_config(Config::from_string(text, "ft.yaml")),
                    Catch::Contains("node.box_max_age") && Catch::Contains("unknown"));
  CHECK(
      FeatureTrackerNodeOptions::from_config(Config::from_string("calibration_file: " + std::string(VIMOT_SOURCE_DIR) +
                                                                     "/config/euroc_stereo.yaml\n"
                                                                     "mode: mono\n",
                                                                 "ft.yaml"))
          .cameras.size() == 1);
}

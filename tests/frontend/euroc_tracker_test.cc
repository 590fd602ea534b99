// The feature tracker on the real EuRoC V1_01 slice (issue 11's quality
// targets): at least 150 static features on every frame after the first,
// median track length >= 10 frames, median stereo epipolar error below
// 0.5 px from the dataset's own calibration. Needs VIMOT_DATA_DIR; without
// it the executable exits with kSkip, which ctest reports as skipped.
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <string>

#include "common/camera/camera_model.h"
#include "common/frontend/asl_stereo_folder.h"
#include "common/frontend/feature_tracker.h"
#include "common/frontend/tracking_stats.h"

namespace {

constexpr int kSkip = 77;  // SKIP_RETURN_CODE in tests/frontend/CMakeLists.txt
std::string g_mav0;

}  // namespace

TEST_CASE("EuRoC V1_01 slice: static features, track length and stereo epipolar error meet the targets") {
  using namespace vimot;
  const std::vector<CameraCalibration> cameras = load_euroc_cameras(g_mav0);
  REQUIRE(cameras.size() == 2);
  const std::vector<frontend::AslStereoPair> pairs = frontend::read_asl_stereo_pairs(g_mav0);
  frontend::FeatureTracker tracker(frontend::FeatureTrackerOptions{}, cameras);
  frontend::TrackingStats stats(cameras);
  int frames = 0;
  for (const frontend::AslStereoPair& p : pairs) {
    if (p.right_path.empty()) continue;
    const cv::Mat left = cv::imread(p.left_path, cv::IMREAD_UNCHANGED);
    const cv::Mat right = cv::imread(p.right_path, cv::IMREAD_UNCHANGED);
    REQUIRE_FALSE(left.empty());
    REQUIRE_FALSE(right.empty());
    const CameraFrame frame = tracker.track(p.timestamp_ns / 1000, left, right, std::nullopt, std::nullopt);
    CHECK(frame.utime == p.timestamp_ns / 1000);
    for (int c = 0; c < 2; ++c) {
      std::set<int64_t> ids;
      for (const FeatureObservation& o : frame.observations) {
        if (o.camera_id == c) REQUIRE(ids.insert(o.feature_id).second);
      }
    }
    stats.add(frame);
    ++frames;
  }
  const frontend::TrackingFigures f = stats.figures();
  INFO(frames << " frames: min static " << f.min_static_per_frame << ", median track " << f.median_track_length
              << " frames, median epipolar " << f.median_epipolar_px << " px over " << f.stereo_observations);
  CHECK(frames == 95);
  CHECK(f.min_static_per_frame >= 150);
  CHECK(f.median_track_length >= 10.0);
  CHECK(f.median_epipolar_px < 0.5);
  // The figure must rest on many stereo points, not a handful.
  CHECK(f.stereo_observations >= 50u * static_cast<std::size_t>(frames));
}

int main(int argc, char* argv[]) {
  const char* root = std::getenv("VIMOT_DATA_DIR");
  if (root == nullptr) {
    std::cout << "VIMOT_DATA_DIR not set: skipping the EuRoC tracker test\n";
    return kSkip;
  }
  g_mav0 = std::string(root) + "/euroc_v101_micro/mav0";
  if (!std::ifstream(g_mav0 + "/cam0/data.csv").good()) {
    std::cout << "VIMOT_DATA_DIR=" << root << " has no euroc_v101_micro/mav0/cam0/data.csv: skipping\n";
    return kSkip;
  }
  return Catch::Session().run(argc, argv);
}

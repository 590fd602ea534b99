// The box chain (common/segmentation/box_chain.h: segmenter then mask
// filter per camera, the offline twin of vimot-segmenter → vimot-mask-filter):
// on a rendered scene without the target the network's false positives
// (which mostly survive the opening: docs/segmented_pipeline.md) are
// reported as detections, and the box they start coasts no longer than
// max_coast_s, never a crash;
// a missing model, a bad config and a wrong camera are clear errors; the
// truth backend gives the box vimot-mask-filter gives for the same masks.
#include <catch2/catch.hpp>

#include <fstream>
#include <string>

#include <opencv2/imgproc.hpp>

#include "common/config/config.h"
#include "common/segmentation/blob.h"
#include "common/segmentation/box_chain.h"
#include "common/segmentation/morphology.h"
#include "common/sim/renderer.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"

using namespace vimot;
using namespace vimot::segmentation;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

BoxChainOptions shipped() {
  return BoxChainOptions::from_config_files(source_path("config/segmenter.yaml"), source_path("config/mask_filter.yaml"));
}

std::string temp_config(const std::string& name, const std::string& text) {
  const std::string path = "/tmp/vimot_box_chain_test_" + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("box chain: a scene without the target, its false positives removed or counted as detections") {
  sim::SimConfig config = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  config.target.enabled = false;
  config.duration = 5.0;
  const sim::Simulator sim(config);
  const sim::Renderer renderer(sim);
  const BoxChainOptions options = shipped();
  BoxChain chain(options, 2);
  const int frames = 8;
  int64_t false_pixels = 0, after_opening = 0, detections = 0, expected_detections = 0;
  int64_t last_fused[2] = {-1, -1};
  for (int k = 0; k < frames; ++k) {
    const int64_t utime = sim.camera_utime(k * sim.camera_frame_count() / frames);
    for (const sim::RenderedView& view : renderer.render(utime)) {
      REQUIRE_FALSE(view.visible);
      const BoxEstimate e = chain.process(view.camera_id, utime, view.image, cv::Mat());
      const cv::Mat& mask = chain.last_mask();
      REQUIRE(mask.size() == view.image.size());
      false_pixels += cv::countNonZero(mask);
      // Independently: what survives the opening, and whether its largest
      // blob is big enough to be a detection.
      const cv::Mat opened = open_mask(mask, options.filter.morphology);
      after_opening += cv::countNonZero(opened);
      const bool blob = largest_blob(opened, options.filter.min_blob_area_px).has_value();
      expected_detections += blob ? 1 : 0;
      detections += e.raw_valid ? 1 : 0;
      CHECK(e.raw_valid == blob);
      // A box only while a fused (false) detection is at most max_coast_s old.
      auto& fused = last_fused[view.camera_id];
      if (e.raw_valid && e.frames_since_raw == 0) fused = utime;
      if (e.filtered_valid) {
        CHECK(fused >= 0);
        CHECK(static_cast<double>(utime - fused) * 1e-6 <= options.filter.kalman.max_coast_s);
      }
    }
  }
  CHECK(after_opening <= false_pixels);
  CHECK(detections == expected_detections);
  WARN("target-free scene, " << frames << " stereo frames: " << false_pixels << " false-positive pixels from the network, "
                             << after_opening << " after the opening, " << detections << " false detections");
}

TEST_CASE("box chain: a missing model, a bad config or a wrong camera is a clear error") {
  BoxChainOptions o = shipped();
  o.segmenter.onnx.model_file = "/nonexistent/model.onnx";
  CHECK_THROWS_WITH(BoxChain(o, 2), Catch::Contains("/nonexistent/model.onnx"));
  CHECK_THROWS_AS(BoxChain(o, 2), SegmenterError);

  const std::string seg = temp_config("segmenter.yaml", "backend: tensorflow\n");
  CHECK_THROWS_WITH(BoxChainOptions::from_config_files(seg, source_path("config/mask_filter.yaml")),
                    Catch::Contains("backend") && Catch::Contains("tensorflow"));
  const std::string filt = temp_config("mask_filter.yaml", "filter:\n  min_blob_area: 5\n");
  CHECK_THROWS_WITH(BoxChainOptions::from_config_files(source_path("config/segmenter.yaml"), filt),
                    Catch::Contains("min_blob_area"));
  CHECK_THROWS_WITH(BoxChainOptions::from_config_files("/nonexistent/segmenter.yaml", filt),
                    Catch::Contains("/nonexistent/segmenter.yaml"));

  BoxChainOptions truth = shipped();
  truth.segmenter.backend = SegmenterOptions::Backend::kTruth;
  BoxChain chain(truth, 1);
  const cv::Mat mask = cv::Mat::zeros(480, 752, CV_8UC1);
  CHECK_THROWS_AS(chain.process(1, 1000, cv::Mat(), mask), std::invalid_argument);
  CHECK_THROWS_AS(BoxChain(truth, 3), std::invalid_argument);
  // A mask of another type is refused by the corruptor, not read.
  CHECK_THROWS_AS(chain.process(0, 1000, cv::Mat(), cv::Mat::zeros(480, 752, CV_32F)), std::invalid_argument);
}

TEST_CASE("box chain, backend truth without corruption: the true box, as the mask filter gives it") {
  BoxChainOptions o = shipped();
  o.segmenter.backend = SegmenterOptions::Backend::kTruth;  // corruption options all zero (shipped config)
  BoxChain chain(o, 2);
  MaskFilter reference(o.filter);
  cv::Mat mask = cv::Mat::zeros(480, 752, CV_8UC1);
  cv::rectangle(mask, cv::Rect(300, 200, 60, 40), cv::Scalar(255), cv::FILLED);
  for (int k = 1; k <= 5; ++k) {
    const int64_t utime = 100000 * k;
    const BoxEstimate e = chain.process(0, utime, cv::Mat(), mask);
    const BoxEstimate r = reference.process(utime, mask);
    CHECK(e.raw_valid);
    CHECK(e.raw_box == Eigen::Vector4d(300, 200, 60, 40));
    CHECK(e.filtered_box == r.filtered_box);
    CHECK(tracker_box(e).value() == e.filtered_box);
  }
  CHECK_FALSE(tracker_box(BoxEstimate{}).has_value());
}

#include "procs/segmenter/segmenter_node.h"

#include <string>
#include <utility>

#include "common/config/config.h"

namespace vimot {

SegmenterNodeOptions SegmenterNodeOptions::from_config(const Config& cfg) {
  cfg.check_keys("", {"backend", "mode", "image_width", "image_height", "onnx", "truth", "channels", "comment"});
  SegmenterNodeOptions o;
  static_cast<segmentation::SegmenterOptions&>(o) = segmentation::SegmenterOptions::from_config(cfg);
  const std::string mode = cfg.get_or<std::string>("mode", "stereo");
  if (mode != "stereo" && mode != "mono") cfg.fail("mode", "must be 'stereo' or 'mono', got '" + mode + "'");
  o.cameras = mode == "stereo" ? 2 : 1;
  o.image_width = cfg.get_or<int>("image_width", o.image_width);
  o.image_height = cfg.get_or<int>("image_height", o.image_height);
  if (o.image_width < 1 || o.image_height < 1) cfg.fail("image_width", "and image_height must be >= 1");
  return o;
}

SegmenterNode::SegmenterNode(const SegmenterNodeOptions& options, MaskCallback on_mask, EventCallback on_event)
    : options_(options), on_mask_(std::move(on_mask)), on_event_(std::move(on_event)) {
  if (uses_truth()) {
    corruptor_ = std::make_unique<segmentation::TruthCorruptor>(options_.truth);
  } else {
    network_ = std::make_unique<segmentation::OnnxSegmenter>(options_.onnx);
  }
}

void SegmenterNode::error(const std::string& what) {
  ++errors_;
  if (on_event_) on_event_({NodeEvent::Kind::kError, what});
}

bool SegmenterNode::accept(const char* what, int camera_id, int64_t utime, const cv::Mat& m) {
  const std::string at = std::string(what) + " of camera " + std::to_string(camera_id) + " at utime " +
                         std::to_string(utime);
  if (camera_id < 0 || camera_id >= options_.cameras) {
    error(at + ": the segmenter has " + std::to_string(options_.cameras) + " camera(s)");
    return false;
  }
  if (m.type() != CV_8UC1 || m.cols != options_.image_width || m.rows != options_.image_height) {
    error(at + " is " + std::to_string(m.cols) + "x" + std::to_string(m.rows) + " (type " +
          std::to_string(m.type()) + "), expected 8-bit grey " + std::to_string(options_.image_width) + "x" +
          std::to_string(options_.image_height) + ": no mask");
    return false;
  }
  return true;
}

void SegmenterNode::on_image(int camera_id, int64_t utime, const cv::Mat& grey) {
  if (uses_truth()) {
    error("an image reached the truth backend, which segments TARGET_MASK_TRUTH only");
    return;
  }
  if (!accept("image", camera_id, utime, grey)) return;
  on_mask_(camera_id, utime, network_->segment(grey));
  ++masks_published_;
}

void SegmenterNode::on_true_mask(int camera_id, int64_t utime, const cv::Mat& mask) {
  if (!uses_truth()) {
    error("a true mask reached the onnx backend, which segments images only");
    return;
  }
  if (!accept("true mask", camera_id, utime, mask)) return;
  on_mask_(camera_id, utime, corruptor_->corrupt(camera_id, mask));
  ++masks_published_;
}

}  // namespace vimot

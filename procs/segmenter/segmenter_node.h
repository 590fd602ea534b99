#pragma once
// The `segmenter` process's logic without LCM (docs/segmenter.md): one
// target mask per camera image. Backend `onnx` runs the network on each
// image (CAM_LEFT / CAM_RIGHT); backend `truth` corrupts each true mask of
// the rendered simulator (TARGET_MASK_TRUTH) as configured. An input of
// the wrong size or type, or from an unknown camera, is a counted error and
// gives no mask. main.cc only converts messages.

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>

#include "common/process/node_event.h"
#include "common/segmentation/segmenter.h"

namespace vimot {

class Config;

/// The segmenter (backend, onnx, truth) and the process's input checks.
struct SegmenterNodeOptions : segmentation::SegmenterOptions {
  int cameras{2};  // stereo 2, mono 1
  /// px; every image / true mask must have this size.
  int image_width{752};
  int image_height{480};

  /// From config/segmenter.yaml: backend (onnx | truth), mode (stereo |
  /// mono), image_width, image_height, onnx (OnnxSegmenterOptions), truth
  /// (TruthCorruptionOptions), channels (the process's), comment. Throws
  /// ConfigError naming the key.
  static SegmenterNodeOptions from_config(const Config& cfg);
};

class SegmenterNode {
 public:
  using MaskCallback = std::function<void(int camera_id, int64_t utime, const cv::Mat& mask)>;
  using EventCallback = std::function<void(const NodeEvent&)>;

  /// Loads the model for `onnx` (segmentation::SegmenterError when unusable).
  SegmenterNode(const SegmenterNodeOptions& options, MaskCallback on_mask, EventCallback on_event);

  bool uses_truth() const { return options_.backend == SegmenterNodeOptions::Backend::kTruth; }
  int cameras() const { return options_.cameras; }

  /// An 8-bit grey camera image (backend onnx).
  void on_image(int camera_id, int64_t utime, const cv::Mat& grey);
  /// The simulator's true mask of an image (backend truth).
  void on_true_mask(int camera_id, int64_t utime, const cv::Mat& mask);

  int64_t masks_published() const { return masks_published_; }
  int64_t errors() const { return errors_; }
  /// Backend truth only: what the corruption did.
  const segmentation::TruthCorruptionCounts* corruption_counts() const {
    return corruptor_ ? &corruptor_->counts() : nullptr;
  }

 private:
  bool accept(const char* what, int camera_id, int64_t utime, const cv::Mat& m);
  void error(const std::string& what);

  SegmenterNodeOptions options_;
  std::unique_ptr<segmentation::OnnxSegmenter> network_;
  std::unique_ptr<segmentation::TruthCorruptor> corruptor_;
  MaskCallback on_mask_;
  EventCallback on_event_;
  int64_t masks_published_{0};
  int64_t errors_{0};
};

}  // namespace vimot

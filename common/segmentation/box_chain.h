#pragma once
// The target box of each camera image without LCM: the segmenter
// (segmenter.h) then the mask filter (mask_filter.h), one of each per
// camera — what vimot-segmenter → vimot-mask-filter compute over LCM, for
// offline evaluations (common/eval/pixel_frontend.h) and benches.
// docs/segmented_pipeline.md.

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/segmentation/mask_filter.h"
#include "common/segmentation/segmenter.h"

namespace vimot::segmentation {

struct BoxChainOptions {
  SegmenterOptions segmenter;
  MaskFilterOptions filter;

  /// From the segmenter's config (config/segmenter.yaml: backend, onnx,
  /// truth) and the mask filter's (config/mask_filter.yaml: filter). Throws
  /// ConfigError naming the file and key.
  static BoxChainOptions from_config_files(const std::string& segmenter_file, const std::string& mask_filter_file);
};

class BoxChain {
 public:
  /// `cameras` (1 or 2) mask filters; loads the model for backend onnx
  /// (SegmenterError when unusable).
  BoxChain(const BoxChainOptions& options, int cameras);

  /// Camera `camera`'s box at `utime` from its 8-bit grey image (backend
  /// onnx) or its true mask (backend truth; the other is not read).
  /// std::invalid_argument for a camera out of range, a wrong type, or a
  /// utime not after the camera's last.
  BoxEstimate process(int camera, int64_t utime, const cv::Mat& image, const cv::Mat& true_mask);

  /// The segmenter's mask of the last process().
  const cv::Mat& last_mask() const { return mask_; }
  /// Backend truth only: what the corruption did.
  const TruthCorruptionCounts* corruption_counts() const { return corruptor_ ? &corruptor_->counts() : nullptr; }

 private:
  std::unique_ptr<OnnxSegmenter> network_;
  std::unique_ptr<TruthCorruptor> corruptor_;
  std::vector<MaskFilter> filters_;
  cv::Mat mask_;
};

/// The box the feature tracker takes from a target box (as
/// procs/feature_tracker does with target_box_t): the filtered one when
/// valid, else the raw one when valid, else none. [x_min, y_min, w, h] px.
std::optional<Eigen::Vector4d> tracker_box(const BoxEstimate& e);

}  // namespace vimot::segmentation

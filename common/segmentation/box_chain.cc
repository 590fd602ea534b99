#include "common/segmentation/box_chain.h"

#include <stdexcept>

#include "common/config/config.h"

namespace vimot::segmentation {

BoxChainOptions BoxChainOptions::from_config_files(const std::string& segmenter_file,
                                                   const std::string& mask_filter_file) {
  BoxChainOptions o;
  o.segmenter = SegmenterOptions::from_config(Config::load_file(segmenter_file));
  o.filter = MaskFilterOptions::from_config(Config::load_file(mask_filter_file), "filter");
  return o;
}

BoxChain::BoxChain(const BoxChainOptions& options, int cameras) {
  if (cameras < 1 || cameras > 2) throw std::invalid_argument("BoxChain: 1 or 2 cameras, got " + std::to_string(cameras));
  if (options.segmenter.backend == SegmenterOptions::Backend::kOnnx) {
    network_ = std::make_unique<OnnxSegmenter>(options.segmenter.onnx);
  } else {
    corruptor_ = std::make_unique<TruthCorruptor>(options.segmenter.truth);
  }
  for (int c = 0; c < cameras; ++c) filters_.emplace_back(options.filter);
}

BoxEstimate BoxChain::process(int camera, int64_t utime, const cv::Mat& image, const cv::Mat& true_mask) {
  if (camera < 0 || camera >= static_cast<int>(filters_.size())) {
    throw std::invalid_argument("BoxChain: camera " + std::to_string(camera) + " of " +
                                std::to_string(filters_.size()));
  }
  mask_ = network_ ? network_->segment(image) : corruptor_->corrupt(camera, true_mask);
  return filters_[static_cast<std::size_t>(camera)].process(utime, mask_);
}

std::optional<Eigen::Vector4d> tracker_box(const BoxEstimate& e) {
  if (e.filtered_valid) return e.filtered_box;
  if (e.raw_valid) return e.raw_box;
  return std::nullopt;
}

}  // namespace vimot::segmentation

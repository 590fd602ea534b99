#pragma once
// Target segmentation of one grey image (docs/segmenter.md), no LCM:
//  - OnnxSegmenter: the shipped network (config/models/segmenter_unet.onnx,
//    trained by scripts/train_segmenter.sh) run by OpenCV's dnn on the CPU.
//    The image is resized (area) to the network input, normalised as
//    (x - mean) * scale, the logits are resized (bilinear) back to the image
//    and thresholded.
//  - TruthCorruptor: the rendered simulator's exact masks made as bad as
//    configured (false-positive blobs, boundary noise, missed frames,
//    dropouts of N frames), to exercise the mask filter. Deterministic: each
//    camera has its own random stream from (seed, camera), so the same mask
//    sequence gives the same output.
// Masks are CV_8UC1, 255 target, 0 background, the image's size.

#include <array>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

namespace vimot {

class Config;

namespace segmentation {

/// A model that cannot be used: what() names the file and what was expected.
class SegmenterError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct OnnxSegmenterOptions {
  std::string model_file;  // path of the .onnx file
  int input_width{320};    // px, the network's input
  int input_height{240};
  double input_mean{127.5};  // network input = (grey - mean) * scale
  double input_scale{1.0 / 127.5};
  double threshold{0.5};  // target where the sigmoid of the logit exceeds this, in (0, 1)

  /// From the `onnx` section of config/segmenter.yaml; model_file relative
  /// to the config file. Throws ConfigError naming the key.
  static OnnxSegmenterOptions from_config(const Config& cfg, const std::string& section);
};

class OnnxSegmenter {
 public:
  /// Loads and checks the model: throws SegmenterError naming the file when
  /// it is missing, not a readable ONNX model, or does not map a
  /// 1x1xHxW input to 1x1xHxW logits (H, W = input size).
  explicit OnnxSegmenter(const OnnxSegmenterOptions& options);

  /// The network's logits (CV_32FC1, input size) for a CV_8UC1 image of any
  /// size (std::invalid_argument for another type or an empty image).
  cv::Mat logits(const cv::Mat& grey);
  /// The mask at the image's size.
  cv::Mat segment(const cv::Mat& grey);

 private:
  cv::Mat forward(const cv::Mat& blob);

  OnnxSegmenterOptions options_;
  cv::dnn::Net net_;
  float logit_threshold_{0.0f};
};

struct TruthCorruptionOptions {
  uint64_t seed{1};
  double miss_probability{0.0};     // a frame's target pixels are lost, that frame only
  double dropout_probability{0.0};  // per frame outside a dropout: a dropout starts
  int dropout_frames{5};            // frames a dropout lasts (target pixels lost)
  double false_blob_rate{0.0};      // mean false-positive blobs per frame (Poisson)
  int false_blob_min_radius{3};     // px, blobs are filled discs
  int false_blob_max_radius{12};
  /// σ (px) of the per-frame boundary shift: the target is dilated (> 0) or
  /// eroded (< 0) by round(N(0, σ)) px.
  double boundary_noise_px{0.0};

  /// From the `truth` section of config/segmenter.yaml. Throws ConfigError.
  static TruthCorruptionOptions from_config(const Config& cfg, const std::string& section);
};

/// What the corruptor did (for tests and the process log).
struct TruthCorruptionCounts {
  int64_t frames{0};
  int64_t missed{0};            // single missed frames
  int64_t dropouts{0};          // dropouts started
  int64_t dropout_frames{0};    // frames inside dropouts
  int64_t false_blobs{0};
};

class TruthCorruptor {
 public:
  /// Throws std::invalid_argument for options out of range.
  explicit TruthCorruptor(const TruthCorruptionOptions& options);

  /// The corrupted copy of camera `camera_id`'s (0 or 1) true mask (CV_8UC1;
  /// std::invalid_argument otherwise).
  cv::Mat corrupt(int camera_id, const cv::Mat& true_mask);

  const TruthCorruptionCounts& counts() const { return counts_; }

 private:
  struct CameraState {
    std::mt19937_64 rng;
    int dropout_left{0};
  };
  TruthCorruptionOptions options_;
  std::array<CameraState, 2> cameras_;
  TruthCorruptionCounts counts_;
};

/// Which segmenter and its options: config/segmenter.yaml's `backend`,
/// `onnx` (read only for backend onnx) and `truth` (read and checked
/// whatever the backend, so a bad section never waits for the day the
/// backend is switched).
struct SegmenterOptions {
  enum class Backend { kOnnx, kTruth };
  Backend backend{Backend::kOnnx};
  OnnxSegmenterOptions onnx;
  TruthCorruptionOptions truth;

  /// Throws ConfigError naming the key.
  static SegmenterOptions from_config(const Config& cfg);
};

}  // namespace segmentation
}  // namespace vimot

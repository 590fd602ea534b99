#include "common/segmentation/segmenter.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "common/config/config.h"

namespace vimot {
namespace segmentation {
namespace {

std::string shape_string(const cv::Mat& m) {
  std::ostringstream s;
  for (int d = 0; d < m.dims; ++d) s << (d ? "x" : "") << m.size[d];
  return s.str();
}

void require_grey(const cv::Mat& image, const char* what) {
  if (image.empty() || image.type() != CV_8UC1) {
    throw std::invalid_argument(std::string(what) + " must be a non-empty 8-bit grey image (CV_8UC1)");
  }
}

}  // namespace

OnnxSegmenterOptions OnnxSegmenterOptions::from_config(const Config& cfg, const std::string& section) {
  cfg.check_keys(section, {"model_file", "input_width", "input_height", "input_mean", "input_scale", "threshold"});
  const Config c = cfg.sub(section);
  OnnxSegmenterOptions o;
  o.model_file = c.resolve_path(c.get<std::string>("model_file"));
  o.input_width = c.get_or<int>("input_width", o.input_width);
  o.input_height = c.get_or<int>("input_height", o.input_height);
  if (o.input_width < 1 || o.input_height < 1) c.fail("input_width", "and input_height must be >= 1");
  o.input_mean = c.get_or<double>("input_mean", o.input_mean);
  o.input_scale = c.get_or<double>("input_scale", o.input_scale);
  o.threshold = c.get_or<double>("threshold", o.threshold);
  if (!(o.threshold > 0.0 && o.threshold < 1.0)) c.fail("threshold", "must be in (0, 1)");
  return o;
}

OnnxSegmenter::OnnxSegmenter(const OnnxSegmenterOptions& options)
    : options_(options),
      logit_threshold_(static_cast<float>(std::log(options.threshold / (1.0 - options.threshold)))) {
  const std::string& file = options_.model_file;
  if (!std::ifstream(file).good()) throw SegmenterError("segmentation model '" + file + "' does not exist or cannot be read");
  try {
    net_ = cv::dnn::readNetFromONNX(file);
  } catch (const cv::Exception& e) {
    throw SegmenterError("segmentation model '" + file + "' is not a readable ONNX model: " + e.err);
  }
  if (net_.empty()) throw SegmenterError("segmentation model '" + file + "' is not a readable ONNX model (empty network)");
  net_.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net_.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  // One forward pass on a blank input proves the shapes now, not mid-run.
  const int in_shape[] = {1, 1, options_.input_height, options_.input_width};
  const std::string expected = "a 1x1x" + std::to_string(options_.input_height) + "x" +
                               std::to_string(options_.input_width) + " grey input mapped to logits of that shape";
  cv::Mat out;
  try {
    out = forward(cv::Mat(4, in_shape, CV_32F, cv::Scalar(0)));
  } catch (const cv::Exception& e) {
    throw SegmenterError("segmentation model '" + file + "' does not accept " + expected + ": " + e.err);
  }
  if (out.dims != 4 || out.size[0] != 1 || out.size[1] != 1 || out.size[2] != options_.input_height ||
      out.size[3] != options_.input_width) {
    throw SegmenterError("segmentation model '" + file + "' gives a " + shape_string(out) + " output, expected " +
                         expected);
  }
}

cv::Mat OnnxSegmenter::forward(const cv::Mat& blob) {
  net_.setInput(blob);
  return net_.forward();
}

cv::Mat OnnxSegmenter::logits(const cv::Mat& grey) {
  require_grey(grey, "segmenter input");
  const cv::Size size(options_.input_width, options_.input_height);
  cv::Mat small;
  if (grey.size() == size) {
    small = grey;
  } else {
    cv::resize(grey, small, size, 0, 0, cv::INTER_AREA);
  }
  const cv::Mat blob = cv::dnn::blobFromImage(small, options_.input_scale, size, cv::Scalar(options_.input_mean));
  const cv::Mat out = forward(blob);
  // 1x1xHxW -> HxW (a copy: the network reuses its output buffer).
  return cv::Mat(options_.input_height, options_.input_width, CV_32F, const_cast<float*>(out.ptr<float>())).clone();
}

cv::Mat OnnxSegmenter::segment(const cv::Mat& grey) {
  cv::Mat l = logits(grey);
  if (l.size() != grey.size()) cv::resize(l, l, grey.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat mask;
  cv::threshold(l, mask, logit_threshold_, 255.0, cv::THRESH_BINARY);
  mask.convertTo(mask, CV_8U);
  return mask;
}

TruthCorruptionOptions TruthCorruptionOptions::from_config(const Config& cfg, const std::string& section) {
  cfg.check_keys(section, {"seed", "miss_probability", "dropout_probability", "dropout_frames", "false_blob_rate",
                           "false_blob_radius", "boundary_noise_px"});
  TruthCorruptionOptions o;
  if (!cfg.has(section)) return o;
  const Config c = cfg.sub(section);
  o.seed = static_cast<uint64_t>(c.get_or<int64_t>("seed", static_cast<int64_t>(o.seed)));
  o.miss_probability = c.get_or<double>("miss_probability", o.miss_probability);
  o.dropout_probability = c.get_or<double>("dropout_probability", o.dropout_probability);
  o.dropout_frames = c.get_or<int>("dropout_frames", o.dropout_frames);
  o.false_blob_rate = c.get_or<double>("false_blob_rate", o.false_blob_rate);
  if (c.has("false_blob_radius")) {
    const std::vector<double> r = c.get_vector("false_blob_radius", 2);
    o.false_blob_min_radius = static_cast<int>(r[0]);
    o.false_blob_max_radius = static_cast<int>(r[1]);
  }
  o.boundary_noise_px = c.get_or<double>("boundary_noise_px", o.boundary_noise_px);
  try {
    TruthCorruptor check(o);
  } catch (const std::invalid_argument& e) {
    c.fail("", e.what());
  }
  return o;
}

TruthCorruptor::TruthCorruptor(const TruthCorruptionOptions& o) : options_(o) {
  auto probability = [](double p) { return p >= 0.0 && p <= 1.0; };
  if (!probability(o.miss_probability) || !probability(o.dropout_probability)) {
    throw std::invalid_argument("miss_probability and dropout_probability must be in [0, 1]");
  }
  if (o.dropout_frames < 1) throw std::invalid_argument("dropout_frames must be >= 1");
  if (!(o.false_blob_rate >= 0.0)) throw std::invalid_argument("false_blob_rate must be >= 0");
  if (o.false_blob_min_radius < 1 || o.false_blob_max_radius < o.false_blob_min_radius) {
    throw std::invalid_argument("false_blob_radius must be [min, max] with 1 <= min <= max");
  }
  if (!(o.boundary_noise_px >= 0.0)) throw std::invalid_argument("boundary_noise_px must be >= 0");
  for (std::size_t k = 0; k < cameras_.size(); ++k) {
    std::seed_seq seq{o.seed, static_cast<uint64_t>(k)};
    cameras_[k].rng.seed(seq);
  }
}

cv::Mat TruthCorruptor::corrupt(int camera_id, const cv::Mat& true_mask) {
  require_grey(true_mask, "true mask");
  if (camera_id < 0 || camera_id >= static_cast<int>(cameras_.size())) {
    throw std::invalid_argument("camera_id must be 0 or 1, got " + std::to_string(camera_id));
  }
  CameraState& cam = cameras_[camera_id];
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ++counts_.frames;
  // Every draw is made every frame, so one option does not shift the random
  // stream of another.
  const bool start_dropout = u(cam.rng) < options_.dropout_probability;
  const bool missed = u(cam.rng) < options_.miss_probability;
  const int shift = static_cast<int>(std::lround(std::normal_distribution<double>(0.0, 1.0)(cam.rng) *
                                                 options_.boundary_noise_px));
  const int blobs = std::poisson_distribution<int>(options_.false_blob_rate)(cam.rng);

  cv::Mat mask;
  if (cam.dropout_left == 0 && start_dropout) {
    cam.dropout_left = options_.dropout_frames;
    ++counts_.dropouts;
  }
  if (cam.dropout_left > 0) {
    --cam.dropout_left;
    ++counts_.dropout_frames;
    mask = cv::Mat::zeros(true_mask.size(), CV_8UC1);
  } else if (missed) {
    ++counts_.missed;
    mask = cv::Mat::zeros(true_mask.size(), CV_8UC1);
  } else {
    cv::threshold(true_mask, mask, 0, 255, cv::THRESH_BINARY);
    if (shift != 0) {
      const cv::Mat kernel =
          cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * std::abs(shift) + 1, 2 * std::abs(shift) + 1));
      if (shift > 0) {
        cv::dilate(mask, mask, kernel);
      } else {
        cv::erode(mask, mask, kernel);
      }
    }
  }
  std::uniform_int_distribution<int> col(0, mask.cols - 1), row(0, mask.rows - 1);
  std::uniform_int_distribution<int> radius(options_.false_blob_min_radius, options_.false_blob_max_radius);
  for (int b = 0; b < blobs; ++b) {
    const cv::Point centre(col(cam.rng), row(cam.rng));
    cv::circle(mask, centre, radius(cam.rng), cv::Scalar(255), cv::FILLED);
  }
  counts_.false_blobs += blobs;
  return mask;
}

SegmenterOptions SegmenterOptions::from_config(const Config& cfg) {
  SegmenterOptions o;
  const std::string backend = cfg.get<std::string>("backend");
  if (backend == "onnx") {
    o.backend = Backend::kOnnx;
    o.onnx = OnnxSegmenterOptions::from_config(cfg, "onnx");
  } else if (backend == "truth") {
    o.backend = Backend::kTruth;
  } else {
    cfg.fail("backend", "must be 'onnx' or 'truth', got '" + backend + "'");
  }
  o.truth = TruthCorruptionOptions::from_config(cfg, "truth");
  return o;
}

}  // namespace segmentation
}  // namespace vimot

#include "common/sim/texture.h"

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace vimot {
namespace sim {

namespace {

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Applies `op` to `image` as if it repeated: pads by `pad` with wrapped
// copies, runs op on the padded image, crops the centre.
template <typename Op>
cv::Mat wrapped(const cv::Mat& image, int pad, Op op) {
  cv::Mat padded;
  cv::copyMakeBorder(image, padded, pad, pad, pad, pad, cv::BORDER_WRAP);
  cv::Mat out = op(padded);
  const int scale = padded.cols / out.cols;  // 1 for filters, 2 for pyrDown
  return out(cv::Rect(pad / scale, pad / scale, image.cols / scale, image.rows / scale)).clone();
}

// Draws one shape of octave size s into `layer` (CV_16SC1) at centre c with
// value `value`, plus its wrapped copies when it crosses a side.
void draw_shape(cv::Mat& layer, std::mt19937_64& rng, double s, int16_t value) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const cv::Point2d c(unit(rng) * layer.cols, unit(rng) * layer.rows);
  const double a = s * (1.0 + unit(rng)), b = s * (1.0 + unit(rng));
  const double kind = unit(rng);
  const double angle = kind < 0.4 ? 0.0 : 180.0 * unit(rng);  // degrees; axis-aligned rectangles first
  const double reach = 0.5 * std::hypot(a, b) + 1.0;
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      const cv::Point2d cc(c.x + dx * layer.cols, c.y + dy * layer.rows);
      if (cc.x + reach < 0 || cc.x - reach > layer.cols || cc.y + reach < 0 || cc.y - reach > layer.rows) continue;
      const cv::RotatedRect shape(cc, cv::Size2d(a, b), angle);
      if (kind < 0.7) {
        cv::Point2f corners[4];
        shape.points(corners);
        cv::Point pts[4];
        for (int k = 0; k < 4; ++k) pts[k] = cv::Point(cvRound(corners[k].x), cvRound(corners[k].y));
        cv::fillConvexPoly(layer, pts, 4, cv::Scalar(value));
      } else {
        cv::ellipse(layer, shape, cv::Scalar(value), cv::FILLED);
      }
    }
  }
}

}  // namespace

cv::Mat make_pattern_texture(int width, int height, const PatternStyle& style, uint64_t seed) {
  if (width <= 0 || height <= 0 || !(style.min_size > 0.0) || !(style.max_size >= style.min_size)) {
    throw std::invalid_argument("make_pattern_texture: sizes must be positive with max_size >= min_size");
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  cv::Mat sum(height, width, CV_32FC1, cv::Scalar(style.base));
  cv::Mat layer(height, width, CV_16SC1);
  // Coarse to fine: octave sizes max/2, max/4, ... down to min_size.
  for (double s = 0.5 * style.max_size; s >= style.min_size * (1.0 - 1e-9); s *= 0.5) {
    layer.setTo(cv::Scalar(0));
    // Mean shape area is (1.5 s)^2.
    const double count = style.coverage * static_cast<double>(width) * height / (2.25 * s * s);
    const long n = std::lround(count);
    for (long k = 0; k < n; ++k) {
      const double magnitude = style.contrast * (0.5 + 0.5 * unit(rng));
      const double sign = unit(rng) < 0.5 ? -1.0 : 1.0;
      draw_shape(layer, rng, s, static_cast<int16_t>(std::lround(sign * magnitude)));
    }
    cv::Mat layer_f;
    layer.convertTo(layer_f, CV_32F);
    sum += layer_f;
  }
  const cv::Mat blurred = wrapped(sum, 4, [](const cv::Mat& in) {
    cv::Mat out;
    cv::GaussianBlur(in, out, cv::Size(5, 5), 0.6, 0.6, cv::BORDER_REFLECT_101);
    return out;
  });
  cv::Mat out;
  blurred.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

cv::Mat make_checkerboard_texture(int width, int height, int square) {
  if (width <= 0 || height <= 0 || square <= 0) {
    throw std::invalid_argument("make_checkerboard_texture: sizes must be positive");
  }
  cv::Mat out(height, width, CV_8UC1);
  for (int y = 0; y < height; ++y) {
    uint8_t* row = out.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) row[x] = ((x / square + y / square) % 2 == 0) ? 40 : 215;
  }
  return out;
}

MipTexture::MipTexture(const cv::Mat& level0) {
  if (level0.type() != CV_8UC1 || !power_of_two(level0.cols) || !power_of_two(level0.rows)) {
    throw std::invalid_argument("MipTexture: the texture must be 8-bit grey with power-of-two sides, got " +
                                std::to_string(level0.cols) + " x " + std::to_string(level0.rows));
  }
  cv::Mat current = level0.clone();
  float scale = 256.0f;
  while (true) {
    Level level;
    level.image = current;
    level.data = current.ptr<uint8_t>(0);
    level.width = current.cols;
    level.height = current.rows;
    level.step = static_cast<int>(current.step[0]);
    level.scale256 = scale;
    levels_.push_back(level);
    if (current.cols <= 4 || current.rows <= 4) break;
    // pyrDown's 5-tap Gaussian, with the texture's own wrap-around as border.
    current = wrapped(current, 4, [](const cv::Mat& in) {
      cv::Mat out;
      cv::pyrDown(in, out);
      return out;
    });
    scale *= 0.5f;
  }
}

}  // namespace sim
}  // namespace vimot

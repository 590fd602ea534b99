#pragma once
// Grey textures for the rendered simulator: procedural patterns with
// corners at several scales, and a mip pyramid sampled trilinearly so a
// surface seen from far away is filtered instead of aliased.
//
// Coordinates: texel (i, j) of level 0 has its centre at (s, t) = (i, j);
// level l is cv::pyrDown of level l-1, whose texel k is centred on texel 2k
// of level l-1, so level l's texel k sits at level-0 coordinate k 2^l. The
// texture repeats (wrap addressing), so the sides are powers of two.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace vimot {
namespace sim {

/// Pattern of independent octave layers: in each octave, rectangles (axis-
/// aligned or rotated) and ellipses of size [s, 2s) texels, each lighter or
/// darker than its surroundings by `contrast` · U(0.5, 1), covering about
/// `coverage` of the area; the layers add up around `base`. Adding (rather
/// than painting over) keeps every octave visible, so when a mip level has
/// averaged the finer octaves away the coarser ones still give corners.
struct PatternStyle {
  double min_size{3.0};    // texels, smallest shape of the finest octave
  double max_size{512.0};  // texels, the coarsest octave starts below this
  double contrast{60.0};   // grey levels, per layer
  double coverage{0.2};    // fraction of the area each octave covers
  double base{128.0};      // grey level the layers add to
};

/// A tileable pattern (shapes crossing a side wrap to the opposite side),
/// CV_8UC1, blurred by σ = 0.6 texel so level 0 has no aliasing of its own.
/// The same seed gives the same image. Throws std::invalid_argument for
/// non-positive sizes.
cv::Mat make_pattern_texture(int width, int height, const PatternStyle& style, uint64_t seed);

/// Checkerboard of `square` texels (dark 40, light 215), square edges
/// between texels, (0, 0) starting a dark square. Tileable when the sides
/// are multiples of 2 · square.
cv::Mat make_checkerboard_texture(int width, int height, int square);

/// A mip pyramid with trilinear, wrapping lookups.
class MipTexture {
 public:
  MipTexture() = default;
  /// `level0`: CV_8UC1 with power-of-two sides (std::invalid_argument
  /// otherwise). Levels are built down to a side of 4 texels.
  explicit MipTexture(const cv::Mat& level0);

  int width() const { return levels_.empty() ? 0 : levels_[0].width; }
  int height() const { return levels_.empty() ? 0 : levels_[0].height; }
  int level_count() const { return static_cast<int>(levels_.size()); }

  /// Grey value at level-0 coordinate (s, t) for a pixel footprint of 2^lod
  /// level-0 texels: bilinear in the two nearest levels, linear between
  /// them; lod <= 0 samples level 0, lod beyond the last level the last.
  float sample(float s, float t, float lod) const {
    if (!(lod > 0.0f)) return bilinear(levels_[0], s, t);
    const int last = static_cast<int>(levels_.size()) - 1;
    if (lod >= static_cast<float>(last)) return bilinear(levels_[static_cast<std::size_t>(last)], s, t);
    const int l = static_cast<int>(lod);
    const float f = lod - static_cast<float>(l);
    const Level& a = levels_[static_cast<std::size_t>(l)];
    const Level& b = levels_[static_cast<std::size_t>(l) + 1];
    return (1.0f - f) * bilinear(a, s, t) + f * bilinear(b, s, t);
  }

 private:
  struct Level {
    cv::Mat image;
    const uint8_t* data{nullptr};
    int width{0}, height{0};
    int step{0};
    float scale{1.0f};  // level-0 coordinate -> this level's coordinate
  };
  static float bilinear(const Level& level, float s, float t) {
    const float x = s * level.scale, y = t * level.scale;
    const float xf = floor_fast(x), yf = floor_fast(y);
    const float fx = x - xf, fy = y - yf;
    // Wrap addressing: the sides are powers of two.
    const int mx = level.width - 1, my = level.height - 1;
    const int x0 = static_cast<int>(xf) & mx, y0 = static_cast<int>(yf) & my;
    const int x1 = (x0 + 1) & mx, y1 = (y0 + 1) & my;
    const uint8_t* r0 = level.data + static_cast<std::ptrdiff_t>(y0) * level.step;
    const uint8_t* r1 = level.data + static_cast<std::ptrdiff_t>(y1) * level.step;
    const float top = static_cast<float>(r0[x0]) + fx * static_cast<float>(r0[x1] - r0[x0]);
    const float bottom = static_cast<float>(r1[x0]) + fx * static_cast<float>(r1[x1] - r1[x0]);
    return top + fy * (bottom - top);
  }
  static float floor_fast(float v) {
    const float i = static_cast<float>(static_cast<int>(v));
    return i > v ? i - 1.0f : i;
  }

  std::vector<Level> levels_;
};

}  // namespace sim
}  // namespace vimot

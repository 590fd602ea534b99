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
  double contrast{40.0};   // grey levels, per layer
  double coverage{0.12};   // fraction of the area each octave covers
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

  /// Grey value at level-0 coordinate (s, t) >= -0.5 for a pixel footprint
  /// of 2^lod level-0 texels: bilinear in the two nearest levels, linear
  /// between them; lod <= 0 samples level 0, lod beyond the last level the
  /// last. Coordinates must stay below 2^22 texels (8-bit fixed point).
  float sample(float s, float t, float lod) const {
    constexpr float kUnit = 1.0f / 65536.0f;
    if (!(lod > 0.0f)) return static_cast<float>(bilinear(levels_[0], s, t)) * kUnit;
    const int last = static_cast<int>(levels_.size()) - 1;
    if (lod >= static_cast<float>(last)) {
      return static_cast<float>(bilinear(levels_[static_cast<std::size_t>(last)], s, t)) * kUnit;
    }
    const int l = static_cast<int>(lod);
    const float f = lod - static_cast<float>(l);
    const float a = static_cast<float>(bilinear(levels_[static_cast<std::size_t>(l)], s, t));
    const float b = static_cast<float>(bilinear(levels_[static_cast<std::size_t>(l) + 1], s, t));
    return (a + f * (b - a)) * kUnit;
  }

 private:
  struct Level {
    cv::Mat image;
    const uint8_t* data{nullptr};
    int width{0}, height{0};
    int step{0};
    float scale256{256.0f};  // level-0 coordinate -> this level's, in 1/256 texel
  };
  // Bilinear value in 1/65536 grey levels, in 8-bit fixed point: no float
  // conversions per texel. Truncation toward zero of s >= -0.5 still floors
  // through the arithmetic shift.
  static int bilinear(const Level& level, float s, float t) {
    const int xi = static_cast<int>(s * level.scale256), yi = static_cast<int>(t * level.scale256);
    const int fx = xi & 255, fy = yi & 255;
    // Wrap addressing: the sides are powers of two.
    const int mx = level.width - 1, my = level.height - 1;
    const int x0 = (xi >> 8) & mx, y0 = (yi >> 8) & my;
    const int x1 = (x0 + 1) & mx, y1 = (y0 + 1) & my;
    const uint8_t* r0 = level.data + static_cast<std::ptrdiff_t>(y0) * level.step;
    const uint8_t* r1 = level.data + static_cast<std::ptrdiff_t>(y1) * level.step;
    const int top = (r0[x0] << 8) + (r0[x1] - r0[x0]) * fx;
    const int bottom = (r1[x0] << 8) + (r1[x1] - r1[x0]) * fx;
    return (top << 8) + (bottom - top) * fy;
  }

  std::vector<Level> levels_;
};

}  // namespace sim
}  // namespace vimot

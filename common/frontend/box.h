#pragma once
// A target bounding box in one camera image, as vimot.target_box_t carries
// it: [x_min, y_min, width, height] in pixels of the raw (distorted) image,
// (0, 0) the centre of the top-left pixel. No LCM here.

namespace vimot::frontend {

struct Box {
  double x_min{0.0};
  double y_min{0.0};
  double width{0.0};
  double height{0.0};

  /// True if (u, v) lies inside the box grown by `margin` pixels on every side.
  bool contains(double u, double v, double margin = 0.0) const {
    return u >= x_min - margin && u <= x_min + width + margin && v >= y_min - margin && v <= y_min + height + margin;
  }
  double center_u() const { return x_min + 0.5 * width; }
  double center_v() const { return y_min + 0.5 * height; }
};

}  // namespace vimot::frontend

#pragma once
// The feature tracker's pixel error on rendered images, against the
// renderer's exact geometry. A track's true point is where the ray of its
// first observation meets the scene (Renderer::surface_at): on the room for
// a static track (fixed in G), on the target for a target track (fixed in
// the target's frame). Every later observation, in either camera, is
// compared with that point's projection through the true poses and the
// camera's lens model; the first observation's own error is zero by
// construction, so the figures measure KLT / ORB drift and stereo
// mismatches, not the corner detector's localisation.

#include <cstdint>
#include <vector>

#include "common/eval/pixel_frontend.h"

namespace vimot {
namespace eval {

/// One observation compared with its track's true point.
struct ObservationError {
  int64_t feature_id{-1};
  int camera_id{0};
  bool is_target{false};     // the tracker's label
  bool born_on_target{false};  // the first observation's ray hit the target
  int age{0};                // frames since the track's first observation
  double error_px{0.0};      // |observed − projected true point|
  double box_distance_px{0.0};  // to the outline of this image's target box: > 0 outside, <= 0 inside, +inf without a box
};

/// Error figures of a set of observations.
struct ErrorSummary {
  int64_t count{0};
  double median_px{0.0};
  double p95_px{0.0};
  double outlier_fraction{0.0};  // error > 3 px
};
ErrorSummary summarise(const std::vector<ObservationError>& errors);

/// Runs `front` over the simulator's camera frames [first, first + frames)
/// and returns the error of every observation after its track's first.
std::vector<ObservationError> tracker_errors(const sim::Simulator& sim, PixelFrontEnd* front, int64_t frames);

}  // namespace eval
}  // namespace vimot

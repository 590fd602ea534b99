#pragma once
// FAST corners on a grid (environment features): each cell of a
// grid_cols x grid_rows grid is topped up to its share of num_features with
// its strongest corners, so features spread over the whole image instead of
// piling up on the most textured patch. No LCM here.

#include <opencv2/core.hpp>
#include <optional>
#include <vector>

#include "common/frontend/box.h"
#include "common/frontend/tracker_options.h"

namespace vimot::frontend {

/// New corners for an 8-bit grey image: none inside `box` (the target's
/// pixels), within options.border_px of the edge, or closer than
/// options.min_distance_px to an `existing` point or to another new corner.
/// Each cell ends with at most ceil(num_features / cells) points, counting
/// the existing ones in it; strongest FAST response first.
std::vector<cv::Point2f> detect_grid_fast(const cv::Mat& image, const std::vector<cv::Point2f>& existing,
                                          const std::optional<Box>& box, const StaticTrackOptions& options);

}  // namespace vimot::frontend

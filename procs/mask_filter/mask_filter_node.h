#pragma once
// The `mask_filter` process's logic without LCM: one MaskFilter
// (common/segmentation) per camera; each camera's masks in, that camera's
// target box out. main.cc only converts messages.
//
// Input checks (counted, never fatal): a camera id the config does not
// have, a mask whose byte count is not width·height, or whose size is not
// the camera's resolution, is an error and produces no box; a mask at or
// before the camera's last utime is dropped; an empty mask (no target
// pixel, or no blob left after the morphology) is a frame without a
// detection — the filter coasts and a box is published.

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/process/node_event.h"
#include "common/segmentation/mask_filter.h"

namespace vimot {

class Config;

struct MaskFilterNodeOptions {
  segmentation::MaskFilterOptions filter;
  /// Expected mask size per camera (cam0, and cam1 for stereo), px.
  std::vector<std::array<int, 2>> resolution;

  /// From a mask filter config (config/mask_filter.yaml): calibration_file
  /// (cameras.cam0/cam1 give the resolution, relative to the file), mode
  /// (stereo | mono), filter (MaskFilterOptions); cameras inline instead of
  /// a calibration_file; `channels` is the
  /// process's. Throws ConfigError naming the key for a bad or unknown key.
  static MaskFilterNodeOptions from_config(const Config& cfg);
};

/// A camera's box of one mask.
struct CameraBox {
  int camera_id{0};
  segmentation::BoxEstimate estimate;
};

class MaskFilterNode {
 public:
  using BoxCallback = std::function<void(const CameraBox&)>;
  using EventCallback = std::function<void(const NodeEvent&)>;

  MaskFilterNode(const MaskFilterNodeOptions& options, BoxCallback on_box, EventCallback on_event);

  /// One mask as vimot.mask_t carries it: its size field and bytes
  /// (row-major, non-zero = target).
  void on_mask(int camera_id, int64_t utime, int width, int height, int64_t size, const std::vector<uint8_t>& data);

  int num_cameras() const { return static_cast<int>(filters_.size()); }
  int64_t masks_processed() const { return masks_processed_; }
  int64_t detections() const { return detections_; }
  int64_t no_detections() const { return no_detections_; }
  int64_t rejected() const { return rejected_; }
  int64_t reinitialised() const { return reinitialised_; }
  int64_t tracks_dropped() const { return tracks_dropped_; }
  int64_t masks_dropped() const { return masks_dropped_; }
  int64_t errors() const { return errors_; }

 private:
  void error(const std::string& what);

  MaskFilterNodeOptions options_;
  std::vector<std::unique_ptr<segmentation::MaskFilter>> filters_;
  std::vector<int64_t> last_utime_;
  BoxCallback on_box_;
  EventCallback on_event_;
  int64_t masks_processed_{0};
  int64_t detections_{0};
  int64_t no_detections_{0};
  int64_t rejected_{0};
  int64_t reinitialised_{0};
  int64_t tracks_dropped_{0};
  int64_t masks_dropped_{0};
  int64_t errors_{0};
};

}  // namespace vimot

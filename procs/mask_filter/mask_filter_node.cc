#include "procs/mask_filter/mask_filter_node.h"

#include <limits>
#include <opencv2/core.hpp>

#include "common/camera/camera_model.h"
#include "common/config/config.h"

namespace vimot {

MaskFilterNodeOptions MaskFilterNodeOptions::from_config(const Config& cfg) {
  // cameras: the calibration inline, when there is no calibration_file.
  cfg.check_keys("", {"calibration_file", "cameras", "mode", "filter", "channels", "comment"});
  MaskFilterNodeOptions o;
  o.filter = segmentation::MaskFilterOptions::from_config(cfg, "filter");
  const Config calib =
      cfg.has("calibration_file") ? Config::load_file(cfg.resolve_path(cfg.get<std::string>("calibration_file"))) : cfg;
  const std::string mode = cfg.get_or<std::string>("mode", "stereo");
  if (mode != "stereo" && mode != "mono") cfg.fail("mode", "must be 'stereo' or 'mono', got '" + mode + "'");
  for (const char* cam : {"cameras.cam0", "cameras.cam1"}) {
    const CameraCalibration c = camera_from_config(calib.sub(cam));
    o.resolution.push_back({c.width, c.height});
    if (mode == "mono") break;
  }
  return o;
}

MaskFilterNode::MaskFilterNode(const MaskFilterNodeOptions& options, BoxCallback on_box, EventCallback on_event)
    : options_(options), on_box_(std::move(on_box)), on_event_(std::move(on_event)) {
  for (std::size_t i = 0; i < options_.resolution.size(); ++i) {
    filters_.push_back(std::make_unique<segmentation::MaskFilter>(options_.filter));
    last_utime_.push_back(std::numeric_limits<int64_t>::min());
  }
}

void MaskFilterNode::error(const std::string& what) {
  ++errors_;
  if (on_event_) on_event_({NodeEvent::Kind::kError, what});
}

void MaskFilterNode::on_mask(int camera_id, int64_t utime, int width, int height, int64_t size,
                             const std::vector<uint8_t>& data) {
  const std::string what = "camera " + std::to_string(camera_id) + " mask at utime " + std::to_string(utime);
  if (camera_id < 0 || camera_id >= num_cameras()) {
    error(what + ": the mask filter has " + std::to_string(num_cameras()) + " camera(s)");
    return;
  }
  const auto [cols, rows] = options_.resolution[static_cast<std::size_t>(camera_id)];
  if (width < 0 || height < 0 || static_cast<int64_t>(width) * height != size ||
      static_cast<std::size_t>(size) != data.size()) {
    error(what + ": size " + std::to_string(size) + " and " + std::to_string(data.size()) + " bytes for " +
          std::to_string(width) + "x" + std::to_string(height));
    return;
  }
  if (width != cols || height != rows) {
    error(what + ": " + std::to_string(width) + "x" + std::to_string(height) + ", expected " + std::to_string(cols) +
          "x" + std::to_string(rows) + " (the calibration)");
    return;
  }
  if (utime <= last_utime_[static_cast<std::size_t>(camera_id)]) {
    ++masks_dropped_;
    if (on_event_) {
      on_event_({NodeEvent::Kind::kDropped, what + ": not after the camera's last mask (" +
                                                std::to_string(last_utime_[static_cast<std::size_t>(camera_id)]) +
                                                ")"});
    }
    return;
  }
  last_utime_[static_cast<std::size_t>(camera_id)] = utime;
  // The filter only reads the mask: wrap the message's bytes, no copy.
  const cv::Mat mask(rows, cols, CV_8UC1, const_cast<uint8_t*>(data.data()));
  CameraBox out;
  out.camera_id = camera_id;
  out.estimate = filters_[static_cast<std::size_t>(camera_id)]->process(utime, mask);
  ++masks_processed_;
  ++(out.estimate.raw_valid ? detections_ : no_detections_);
  using Outcome = segmentation::BoxKalmanFilter::Outcome;
  switch (out.estimate.outcome) {
    case Outcome::kRejected: ++rejected_; break;
    case Outcome::kReinitialised:
      ++reinitialised_;
      if (on_event_) on_event_({NodeEvent::Kind::kInfo, what + ": box filter re-initialised (detections kept off the gate)"});
      break;
    case Outcome::kDropped:
      ++tracks_dropped_;
      if (on_event_) on_event_({NodeEvent::Kind::kInfo, what + ": target box dropped (no detection for too long)"});
      break;
    default: break;
  }
  if (on_box_) on_box_(out);
}

}  // namespace vimot

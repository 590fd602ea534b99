#include "procs/feature_tracker/feature_tracker_node.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/config/config.h"

namespace vimot {

namespace {
// Boxes and masks kept per camera: enough for one arriving a few frames ahead.
constexpr std::size_t kMaxStored = 16;
}  // namespace

FeatureTrackerNodeOptions FeatureTrackerNodeOptions::from_config(const Config& cfg) {
  const std::vector<std::string> allowed{"calibration_file", "mode", "tracker", "node", "channels", "comment"};
  const std::vector<std::string> node_keys{"max_pending_images", "box_max_age_s", "wait_for_box", "box_wait_frames"};
  for (const std::string& k : cfg.keys()) {
    if (std::find(allowed.begin(), allowed.end(), k) == allowed.end()) {
      cfg.fail(k, "is unknown (expected calibration_file, mode, tracker, node, channels, comment)");
    }
  }
  if (cfg.has("node")) {
    for (const std::string& k : cfg.sub("node").keys()) {
      if (std::find(node_keys.begin(), node_keys.end(), k) == node_keys.end()) {
        cfg.fail("node." + k, "is unknown (expected max_pending_images, box_max_age_s, wait_for_box, box_wait_frames)");
      }
    }
  }
  FeatureTrackerNodeOptions o;
  o.tracker = frontend::FeatureTrackerOptions::from_config(cfg, "tracker");
  const Config calib =
      cfg.has("calibration_file") ? Config::load_file(cfg.resolve_path(cfg.get<std::string>("calibration_file"))) : cfg;
  const std::string mode = cfg.get_or<std::string>("mode", "stereo");
  if (mode != "stereo" && mode != "mono") cfg.fail("mode", "must be 'stereo' or 'mono', got '" + mode + "'");
  o.cameras.push_back(camera_from_config(calib.sub("cameras.cam0")));
  if (mode == "stereo") o.cameras.push_back(camera_from_config(calib.sub("cameras.cam1")));
  o.max_pending_images = cfg.get_or<int>("node.max_pending_images", o.max_pending_images);
  if (o.max_pending_images < 1) cfg.fail("node.max_pending_images", "must be >= 1");
  o.wait_for_box = cfg.get_or<bool>("node.wait_for_box", o.wait_for_box);
  o.box_wait_frames = cfg.get_or<int>("node.box_wait_frames", o.box_wait_frames);
  if (o.box_wait_frames < 1) cfg.fail("node.box_wait_frames", "must be >= 1");
  o.box_max_age_s = cfg.get_or<double>("node.box_max_age_s", o.box_max_age_s);
  if (o.box_max_age_s < 0.0) cfg.fail("node.box_max_age_s", "must be >= 0");
  return o;
}

FeatureTrackerNode::FeatureTrackerNode(const FeatureTrackerNodeOptions& options, FrameCallback on_frame,
                                       EventCallback on_event)
    : options_(options),
      tracker_(options.tracker, options.cameras),
      on_frame_(std::move(on_frame)),
      on_event_(std::move(on_event)),
      boxes_(options.cameras.size(), ByUtime<std::optional<frontend::Box>>(kMaxStored)),
      masks_(options.cameras.size(), ByUtime<cv::Mat>(kMaxStored)) {}

void FeatureTrackerNode::drop(const std::string& why) {
  ++images_dropped_;
  if (on_event_) on_event_({NodeEvent::Kind::kDropped, why});
}

void FeatureTrackerNode::error(const std::string& what) {
  ++errors_;
  if (on_event_) on_event_({NodeEvent::Kind::kError, what});
}

bool FeatureTrackerNode::known_camera(int camera_id, const std::string& what) {
  if (camera_id >= 0 && camera_id < static_cast<int>(options_.cameras.size())) return true;
  error(what + " for camera " + std::to_string(camera_id) + ", the tracker has " +
        std::to_string(options_.cameras.size()));
  return false;
}

void FeatureTrackerNode::on_box(int camera_id, int64_t utime, std::optional<frontend::Box> box) {
  if (!known_camera(camera_id, "target box")) return;
  if (box && !(std::isfinite(box->x_min) && std::isfinite(box->y_min) && std::isfinite(box->width) &&
               std::isfinite(box->height) && box->width >= 0.0 && box->height >= 0.0)) {
    error("target box of camera " + std::to_string(camera_id) + " at utime " + std::to_string(utime) +
          " is not finite or has a negative size: taken as no box");
    box.reset();
  }
  boxes_[static_cast<std::size_t>(camera_id)].put(utime, box);
  release_ready();
}

void FeatureTrackerNode::on_mask(int camera_id, int64_t utime, const cv::Mat& mask) {
  if (!uses_mask() || !known_camera(camera_id, "target mask")) return;
  const CameraCalibration& c = options_.cameras[static_cast<std::size_t>(camera_id)];
  cv::Mat usable = mask;
  if (mask.type() != CV_8UC1 || mask.cols != c.width || mask.rows != c.height) {
    error("target mask of camera " + std::to_string(camera_id) + " at utime " + std::to_string(utime) + " is " +
          std::to_string(mask.cols) + "x" + std::to_string(mask.rows) + " type " + std::to_string(mask.type()) +
          ", expected 8-bit " + std::to_string(c.width) + "x" + std::to_string(c.height) + ": taken as no mask");
    usable = cv::Mat();
  }
  masks_[static_cast<std::size_t>(camera_id)].put(utime, usable);
  release_ready();
}

std::optional<frontend::Box> FeatureTrackerNode::box_for(int camera_id, int64_t utime) const {
  const auto* box = boxes_[static_cast<std::size_t>(camera_id)].at(utime, options_.box_max_age_s * 1e6);
  return box ? *box : std::nullopt;
}

cv::Mat FeatureTrackerNode::mask_for(int camera_id, int64_t utime) const {
  const cv::Mat* mask = masks_[static_cast<std::size_t>(camera_id)].at(utime, options_.box_max_age_s * 1e6);
  return mask ? *mask : cv::Mat();
}

void FeatureTrackerNode::on_image(int camera_id, int64_t utime, const cv::Mat& image) {
  const std::string what = "camera " + std::to_string(camera_id) + " image at utime " + std::to_string(utime);
  if (camera_id < 0 || camera_id >= static_cast<int>(options_.cameras.size())) {
    error(what + ": the tracker has " + std::to_string(options_.cameras.size()) + " camera(s)");
    return;
  }
  const CameraCalibration& c = options_.cameras[static_cast<std::size_t>(camera_id)];
  if (image.type() != CV_8UC1 || image.cols != c.width || image.rows != c.height) {
    error(what + ": " + std::to_string(image.cols) + "x" + std::to_string(image.rows) + " type " +
          std::to_string(image.type()) + ", expected 8-bit grey " + std::to_string(c.width) + "x" +
          std::to_string(c.height) + " (the calibration)");
    return;
  }
  if (utime <= last_utime_) {
    drop(what + ": not after the last tracked frame (" + std::to_string(last_utime_) + ")");
    return;
  }
  if (!stereo()) {
    frame_ready(utime, image, cv::Mat());
    return;
  }
  auto& mine = pending_[camera_id];
  auto& other = pending_[1 - camera_id];
  const auto partner = other.find(utime);
  if (partner == other.end()) {
    if (!mine.emplace(utime, image).second) {
      drop(what + ": a second image at this utime");
      return;
    }
    while (mine.size() > static_cast<std::size_t>(options_.max_pending_images)) {
      drop("camera " + std::to_string(camera_id) + " image at utime " + std::to_string(mine.begin()->first) +
           ": no partner among " + std::to_string(options_.max_pending_images) + " pending images");
      mine.erase(mine.begin());
    }
    return;
  }
  const cv::Mat partner_image = partner->second;
  // Everything pending up to this pair is now too old to be tracked.
  for (int cam = 0; cam < 2; ++cam) {
    auto& p = pending_[cam];
    while (!p.empty() && p.begin()->first <= utime) {
      if (p.begin()->first < utime) {
        drop("camera " + std::to_string(cam) + " image at utime " + std::to_string(p.begin()->first) +
             ": its partner never came");
      }
      p.erase(p.begin());
    }
  }
  if (camera_id == 0) {
    frame_ready(utime, image, partner_image);
  } else {
    frame_ready(utime, partner_image, image);
  }
}

void FeatureTrackerNode::frame_ready(int64_t utime, const cv::Mat& left, const cv::Mat& right) {
  if (!options_.wait_for_box) {
    process(utime, left, right);
    return;
  }
  ready_.emplace(utime, std::make_pair(left, right));
  release_ready();
}

void FeatureTrackerNode::release_ready() {
  // A frame waits for its boxes; once box_wait_frames later frames are
  // complete too, the boxes of the earlier one are taken as missing (the
  // box source skipped it) so a silent box channel delays the output by
  // that many frames, no more. Likewise the masks.
  while (!ready_.empty()) {
    const auto it = ready_.begin();
    bool boxes_in = true;
    for (std::size_t c = 0; c < options_.cameras.size(); ++c) {
      boxes_in = boxes_in && boxes_[c].has(it->first) && (!uses_mask() || masks_[c].has(it->first));
    }
    if (!boxes_in && ready_.size() <= static_cast<std::size_t>(options_.box_wait_frames)) return;
    const auto [left, right] = it->second;
    const int64_t utime = it->first;
    ready_.erase(it);
    process(utime, left, right);
  }
}

void FeatureTrackerNode::flush() {
  while (!ready_.empty()) {
    const auto it = ready_.begin();
    const auto [left, right] = it->second;
    const int64_t utime = it->first;
    ready_.erase(it);
    process(utime, left, right);
  }
}

void FeatureTrackerNode::process(int64_t utime, const cv::Mat& left, const cv::Mat& right) {
  try {
    const CameraFrame frame =
        tracker_.track(utime, left, right, box_for(0, utime), stereo() ? box_for(1, utime) : std::nullopt,
                       mask_for(0, utime), stereo() ? mask_for(1, utime) : cv::Mat());
    last_utime_ = utime;
    ++frames_tracked_;
    if (on_frame_) on_frame_(frame);
  } catch (const std::invalid_argument& e) {
    error(std::string("frame at utime ") + std::to_string(utime) + ": " + e.what());
  }
}

}  // namespace vimot

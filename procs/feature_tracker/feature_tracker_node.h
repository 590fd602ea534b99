#pragma once
// The `feature_tracker` process's logic without LCM: pairs left and right
// images by equal utime, attaches each camera's target box, runs the
// tracker (common/frontend) and says what to publish. main.cc only converts
// messages.
//
// Pairing rule: a stereo frame is tracked when both images of one utime
// have arrived; images older than a tracked frame that never found their
// partner are dropped (counted), as are images at or before the last
// tracked utime. Boxes: the latest box of the camera at or before the
// frame's utime and at most box_max_age_s older. With wait_for_box a
// complete frame is held until every camera's box of its utime has arrived
// (or a later frame is complete), so a box published after its images is
// still used and a live run equals a replay; without it a box arriving after
// its images is too late for them. Masks (tracker.target.use_mask) are
// paired and waited for as the boxes, by the same rules.

#include <cstdint>
#include <functional>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/camera/camera_model.h"
#include "common/frontend/box.h"
#include "common/frontend/feature_tracker.h"
#include "common/frontend/tracker_options.h"
#include "common/process/node_event.h"
#include "common/types/sensor_data.h"

namespace vimot {

class Config;

/// One camera's messages by utime (target boxes, masks), the newest
/// `capacity` kept.
template <typename T>
class ByUtime {
 public:
  explicit ByUtime(std::size_t capacity) : capacity_(capacity) {}
  void put(int64_t utime, T value) {
    items_[utime] = std::move(value);
    while (items_.size() > capacity_) items_.erase(items_.begin());
  }
  bool has(int64_t utime) const { return items_.count(utime) != 0; }
  /// The latest at or before `utime` and at most `max_age_us` older; null if none.
  const T* at(int64_t utime, double max_age_us) const {
    auto it = items_.upper_bound(utime);
    if (it == items_.begin()) return nullptr;
    --it;
    return static_cast<double>(utime - it->first) > max_age_us ? nullptr : &it->second;
  }

 private:
  std::size_t capacity_;
  std::map<int64_t, T> items_;
};

struct FeatureTrackerNodeOptions {
  frontend::FeatureTrackerOptions tracker;
  /// cam0 (and cam1 for stereo).
  std::vector<CameraCalibration> cameras;
  /// Images held per camera while waiting for their partner.
  int max_pending_images{4};
  /// A box (or mask) older than this (s) than the image is not used.
  double box_max_age_s{0.2};
  /// Hold each frame for its boxes (a box source runs: mask filter, the
  /// simulator's truth box), and its masks with tracker.target.use_mask;
  /// false: track as soon as the images are there.
  bool wait_for_box{false};
  /// With wait_for_box: a frame goes out without its missing boxes once
  /// this many later frames are complete (>= 1; a slow box source such as
  /// the segmentation network needs more than one frame).
  int box_wait_frames{1};

  /// From a feature tracker config (config/feature_tracker.yaml):
  /// calibration_file (cameras.cam0/cam1, relative to the file), mode
  /// (stereo | mono), tracker (FeatureTrackerOptions), node
  /// (max_pending_images, box_max_age_s, wait_for_box); `channels` is the
  /// process's.
  /// Throws ConfigError naming the key for a bad or unknown key.
  static FeatureTrackerNodeOptions from_config(const Config& cfg);
};

class FeatureTrackerNode {
 public:
  using FrameCallback = std::function<void(const CameraFrame&)>;
  using EventCallback = std::function<void(const NodeEvent&)>;

  FeatureTrackerNode(const FeatureTrackerNodeOptions& options, FrameCallback on_frame, EventCallback on_event);

  /// An 8-bit grey image of camera 0 (left) or 1 (right).
  void on_image(int camera_id, int64_t utime, const cv::Mat& image);
  /// The target box of a camera at an image's utime; nullopt: no valid box.
  void on_box(int camera_id, int64_t utime, std::optional<frontend::Box> box);
  /// The target mask of a camera at an image's utime (8-bit of the image's
  /// size, nonzero = target); used with tracker.target.use_mask only.
  void on_mask(int camera_id, int64_t utime, const cv::Mat& mask);
  bool uses_mask() const { return options_.tracker.target.use_mask; }
  /// Tracks every frame still waiting for its boxes (end of input).
  void flush();

  bool stereo() const { return options_.cameras.size() == 2; }
  int64_t frames_tracked() const { return frames_tracked_; }
  int64_t images_dropped() const { return images_dropped_; }
  int64_t errors() const { return errors_; }
  const frontend::FeatureTracker& tracker() const { return tracker_; }

 private:
  void frame_ready(int64_t utime, const cv::Mat& left, const cv::Mat& right);
  void release_ready();
  void process(int64_t utime, const cv::Mat& left, const cv::Mat& right);
  std::optional<frontend::Box> box_for(int camera_id, int64_t utime) const;
  cv::Mat mask_for(int camera_id, int64_t utime) const;
  bool known_camera(int camera_id, const std::string& what);
  void drop(const std::string& why);
  void error(const std::string& what);

  FeatureTrackerNodeOptions options_;
  frontend::FeatureTracker tracker_;
  FrameCallback on_frame_;
  EventCallback on_event_;
  std::map<int64_t, cv::Mat> pending_[2];
  std::vector<ByUtime<std::optional<frontend::Box>>> boxes_;
  std::vector<ByUtime<cv::Mat>> masks_;  // empty Mat: the camera's mask was unusable
  std::map<int64_t, std::pair<cv::Mat, cv::Mat>> ready_;  // complete frames waiting for boxes
  int64_t last_utime_{-1};
  int64_t frames_tracked_{0};
  int64_t images_dropped_{0};
  int64_t errors_{0};
};

}  // namespace vimot

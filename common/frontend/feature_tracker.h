#pragma once
// The visual front end (Section VI-B of the Schmidt-EKF paper): grey images
// of one or two cameras in, a CameraFrame of feature observations out — the
// same plain type the simulator emits, so the estimators do not change.
//
// Environment (static) features: FAST on a grid over the image minus the
// target box (grid_detector.h), pyramidal KLT frame to frame in each camera
// and left to right for stereo points. Target features: ORB inside the box
// (orb_features.h), matched by descriptor frame to frame and left to right;
// a new target track is matched against the stored target points
// (target_point_store.h) and re-uses the id of the point it re-finds.
// Optionally (target.frame_to_frame / stereo klt, anchor_align) target
// points are followed by KLT, anchored, and matched left to right by KLT,
// ORB only detecting new ones and closing loops. Every
// match set (per camera frame to frame, stereo; static and target apart) is
// cleaned by 8-point RANSAC (epipolar_ransac.h).
//
// Track ids: stable across frames, unique within a run, the same in both
// cameras for a stereo point. No LCM here.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <random>
#include <vector>

#include "common/camera/camera_model.h"
#include "common/frontend/anchor_patch.h"
#include "common/frontend/box.h"
#include "common/frontend/epipolar_ransac.h"
#include "common/frontend/orb_features.h"
#include "common/frontend/target_point_store.h"
#include "common/frontend/tracker_options.h"
#include "common/types/sensor_data.h"

namespace vimot::frontend {

/// Wall time of each stage of the last track() call (ms), for the
/// benchmark's profile.
struct TrackerTiming {
  double preprocess_ms{0.0};       // histogram equalisation + KLT pyramids
  double static_temporal_ms{0.0};  // KLT frame to frame + RANSAC, both cameras
  double detect_ms{0.0};           // FAST grid + undistortion of new corners
  double static_stereo_ms{0.0};    // KLT left to right + RANSAC
  double target_ms{0.0};           // ORB, matching, RANSAC, loop closure
  double total_ms{0.0};
};

class FeatureTracker {
 public:
  /// One camera (mono) or two (stereo: cam0 left, cam1 right). Throws
  /// std::invalid_argument for another count or invalid options.
  FeatureTracker(const FeatureTrackerOptions& options, const std::vector<CameraCalibration>& cameras);

  /// Tracks one (stereo) frame. `left` / `right`: 8-bit grey images of the
  /// calibrated size (`right` empty for mono). Boxes: the target in each
  /// image, [x_min, y_min, width, height] raw pixels; without a box every
  /// feature of that image is static. Masks (target.use_mask; ignored
  /// otherwise): each image's target mask, 8-bit of the image's size,
  /// nonzero = target; empty = none. Throws std::invalid_argument (the
  /// tracker unchanged) for a wrong image or mask size or type, a missing or
  /// superfluous right image, a right box or mask given to a mono tracker, a
  /// non-finite or negative box, or a utime not after the previous frame's.
  CameraFrame track(int64_t utime, const cv::Mat& left, const cv::Mat& right, std::optional<Box> box_left,
                    std::optional<Box> box_right, const cv::Mat& mask_left = cv::Mat(),
                    const cv::Mat& mask_right = cv::Mat());

  int num_cameras() const { return static_cast<int>(cameras_.size()); }
  /// Target tracks that got an old id back by descriptor (loop closures).
  int64_t loop_closures() const { return loop_closures_; }
  const TrackerTiming& last_timing() const { return timing_; }

 private:
  struct Point {
    int64_t id{-1};
    cv::Point2f pixel;
    Eigen::Vector2d normalized{Eigen::Vector2d::Zero()};
    int64_t born_frame{0};  // frame index of the track's first corner
    // static.anchor_align: the patch of the track's anchor image and its
    // warp into the current image (shared: a Point is copied each frame).
    std::shared_ptr<const AnchorPatch> anchor;
    Eigen::Matrix2f affine{Eigen::Matrix2f::Identity()};
  };
  struct TargetPoint {
    Point point;
    Descriptor descriptor{};
  };
  using PixelTest = std::function<bool(const cv::Point2f&)>;

  void check_input(int64_t utime, const cv::Mat& left, const cv::Mat& right, const std::optional<Box>& box_left,
                   const std::optional<Box>& box_right, const cv::Mat& mask_left, const cv::Mat& mask_right) const;
  bool normalize(int cam, Point* p) const;
  bool usable(int cam, const cv::Point2f& px, const std::optional<Box>& box) const;
  void track_static_temporal(int cam, const std::optional<Box>& box);
  /// static.anchor_align: takes `p`'s anchor patch in camera `cam`'s current
  /// image; false if it cannot be taken (edge of the image, too little texture).
  bool anchor(int cam, Point* p) const;
  /// `p` refined against its anchor patch in camera `cam`'s current image,
  /// re-anchored if deformed; nullopt if the anchor no longer matches.
  std::optional<Point> aligned(int cam, const Point& p) const;
  /// aligned() for each point; drops those that fail it or `keep`.
  void align_to_anchors(int cam, const PixelTest& keep, std::vector<Point>* points) const;
  void detect_static(const std::optional<Box>& box);
  void match_static_stereo(const std::optional<Box>& box_right);
  void track_target(const std::vector<cv::Mat>& images, const std::vector<std::optional<Box>>& boxes);
  /// target.frame_to_frame klt: the previous frame's target points of `cam`
  /// followed into this frame by KLT (the guess shifted by the box's
  /// motion), kept inside `box`, cleaned by RANSAC; ids and descriptors kept.
  std::vector<TargetPoint> klt_target(int cam, const Box& box);
  /// target.stereo klt: each left target point of `cur` without a right
  /// partner looked for in the right image by KLT (kept inside `box_right`),
  /// then one stereo RANSAC over the target pairs.
  void match_target_stereo_klt(const Box& box_right, std::vector<std::vector<TargetPoint>>* cur);
  /// Keep flags for `right`: false for a point whose left partner (same id)
  /// RANSAC rejects as a stereo pair.
  std::vector<bool> stereo_inliers(const std::vector<Point>& left, const std::vector<Point>& right);
  /// Inside `box` and camera `cam`'s image, and on its eroded target mask
  /// if it has one.
  bool on_target(int cam, const cv::Point2f& px, const Box& box) const;
  /// KLT from one pyramid to another, the guess shifted by `shift`; keeps
  /// points that converge where `keep` says, with an undistortable pixel.
  std::vector<Point> klt(const std::vector<cv::Mat>& from_pyr, int to_cam, const std::vector<cv::Mat>& to_pyr,
                         const std::vector<Point>& points, cv::Point2f shift, const PixelTest& keep) const;
  double focal(int cam_a, int cam_b) const;

  FeatureTrackerOptions options_;
  std::vector<CameraModel> cameras_;
  EpipolarRansac ransac_;
  OrbBoxDetector orb_;
  TargetPointStore store_;

  int64_t next_id_{0};
  int64_t first_new_id_{0};  // ids from here on were detected this frame
  int64_t frame_index_{0};
  int64_t last_utime_{0};
  int64_t loop_closures_{0};
  TrackerTiming timing_;
  // Per camera: the previous frame's pyramid, static points, target points
  // and box; `pyramid_` is the current frame's during track().
  std::vector<std::vector<cv::Mat>> prev_pyramid_, pyramid_;
  std::vector<std::vector<Point>> static_;
  std::vector<std::vector<TargetPoint>> target_;
  std::vector<std::optional<Box>> prev_box_;
  // Per camera, this frame's target mask eroded (target.use_mask); empty:
  // none.
  std::vector<cv::Mat> eroded_mask_;
};

}  // namespace vimot::frontend

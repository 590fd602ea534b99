#pragma once
// Options of the feature tracker (common/frontend), read from config in one
// place. Keys under the section (config/feature_tracker.yaml, `tracker:`):
//   static:  equalize, num_features, grid_cols, grid_rows, fast_threshold,
//            min_distance_px, border_px, klt_window_px, klt_pyramid_levels,
//            klt_max_iterations, klt_epsilon, max_track_frames, anchor_align,
//            anchor_min_zncc, anchor_max_correction_px, anchor_max_scale
//   target:  num_features, orb_fast_threshold, orb_levels, orb_scale_factor,
//            max_hamming, match_ratio, max_motion_px, loop_closure_max_hamming,
//            max_stored_points, frame_to_frame, min_distance_px, stereo,
//            anchor_align, grid, use_mask
//   ransac:  threshold_px, confidence, max_iterations, min_points, seed
// Every key is optional; an unknown key is an error naming it. Meanings and
// defaults: docs/feature_tracker.md.

#include <cstdint>
#include <string>

namespace vimot {
class Config;
}

namespace vimot::frontend {

/// FAST on a grid + pyramidal KLT (environment features).
struct StaticTrackOptions {
  bool equalize{true};    // histogram-equalise each image first (camera gain differences)
  int num_features{200};  // wanted per camera; FAST tops the left image up to this
  int grid_cols{8};       // detection grid: each cell gets num_features / cells
  int grid_rows{5};
  int fast_threshold{15};      // FAST intensity threshold (grey levels)
  double min_distance_px{15};  // no new corner this close to a tracked one
  int border_px{8};            // corners and tracks keep this far from the image edge
  int klt_window_px{15};       // KLT window side (odd)
  int klt_pyramid_levels{3};   // levels above the full image
  int klt_max_iterations{20};
  double klt_epsilon{0.03};  // px, KLT stop criterion
  // A static track older than this many frames is ended (its point is
  // re-detected under a new id): KLT's error grows with a track's age
  // (docs/feature_tracker.md). 0 = no limit.
  int max_track_frames{0};
  // Anchored tracks (anchor_patch.h): each frame-to-frame KLT position is
  // refined by aligning the patch of the track's anchor image (affine warp,
  // gain/offset) so the error does not accumulate. A track whose aligned
  // patch correlates below anchor_min_zncc, or whose alignment moves the
  // KLT position by more than anchor_max_correction_px, ends; one whose
  // warp has scaled the patch beyond anchor_max_scale (either way) takes
  // its current patch as the new anchor.
  bool anchor_align{false};
  double anchor_min_zncc{0.8};
  double anchor_max_correction_px{2.0};
  double anchor_max_scale{1.3};
  /// Static features keep this far (px) from the target box: a KLT window
  /// overlapping the target follows the target's motion, not the room's.
  int box_margin_px() const { return klt_window_px / 2; }
  /// target.use_mask erodes the target mask by this (px): a point's KLT
  /// window reaches klt_window_px / 2 px either side of a sub-pixel
  /// position, and its bilinear samples one pixel further from the rounded
  /// one, so half the window rounded up keeps the whole window on the target.
  int target_mask_erode_px() const { return (klt_window_px + 1) / 2; }
  void validate() const;
};

/// ORB inside the target box (target features).
struct TargetTrackOptions {
  int num_features{80};        // ORB keypoints per camera in the box
  int orb_fast_threshold{10};  // lower than static: a box is small
  int orb_levels{4};
  double orb_scale_factor{1.2};
  int max_hamming{60};               // of 256 bits: a frame-to-frame / stereo match
  double match_ratio{0.8};           // best / second-best distance (Lowe)
  double max_motion_px{80.0};        // frame to frame, after the box's own motion
  int loop_closure_max_hamming{40};  // stricter: no geometry checks a re-identification
  int max_stored_points{500};        // descriptors kept for loop closure (oldest dropped)
  // Frame to frame: "orb" re-detects every frame and matches descriptors
  // (a point continues only if ORB finds it again: ~55 % per frame on a
  // small box); "klt" follows the previous frame's points by pyramidal KLT
  // (the static options' window, levels and stop criteria) and tops up with
  // ORB corners at least min_distance_px from a tracked point. Long tracks
  // are what the monocular object tracker's initialisation needs.
  std::string frame_to_frame{"orb"};
  double min_distance_px{5.0};  // "klt": no new corner this close to a tracked target point
  bool klt() const { return frame_to_frame == "klt"; }
  // Left to right: "descriptor" detects ORB in the right box too and matches
  // descriptors (ORB's keypoint positions err by ~0.8 px, which the
  // disparity takes straight into the depth); "klt" (with frame_to_frame
  // klt) finds each left target point without a right partner in the right
  // image by KLT, as the static points, and follows right points frame to
  // frame like the left ones: no ORB in the right image.
  std::string stereo{"descriptor"};
  bool stereo_klt() const { return stereo == "klt"; }
  // frame_to_frame klt: each KLT position refined against the track's
  // anchor patch (the static anchor_* options), so a target track does not
  // drift as it lives on.
  bool anchor_align{false};
  // The box split into grid x grid cells, each holding at most
  // ceil(num_features / grid²) target points (followed ones first), new
  // ORB corners taken strongest first per cell. ORB ranks corners by their
  // Harris response, which grows with the fourth power of the contrast, so
  // with one cell (grid 1) a brightly lit face takes every slot and the
  // shaded faces of the same object get none; points on one face only are
  // a planar structure the monocular object tracker cannot resolve.
  int grid{1};
  // Target points detected and kept only where the target mask given to
  // FeatureTracker::track, eroded by static target_mask_erode_px(), is set:
  // a point whose KLT / anchor window holds the background behind the
  // silhouette follows neither the target nor the background. Without a
  // mask for an image the box alone bounds its target points.
  bool use_mask{false};
  void validate() const;
};

/// 8-point RANSAC on the fundamental matrix of undistorted points.
struct RansacOptions {
  double threshold_px{1.0};  // Sampson distance, converted to normalized units by the focal length
  double confidence{0.99};   // stop once an all-inlier sample is this likely to have been drawn
  int max_iterations{200};
  int min_points{10};  // below this no model is fitted and every match is kept
  uint64_t seed{1};    // the sampling is deterministic for a seed
  void validate() const;
};

struct FeatureTrackerOptions {
  StaticTrackOptions static_tracks;
  TargetTrackOptions target;
  RansacOptions ransac;

  /// Throws std::invalid_argument naming the first invalid option.
  void validate() const;

  /// Reads `section` of `cfg` (absent keys keep the defaults); throws
  /// ConfigError naming the file and key for a bad value or unknown key.
  static FeatureTrackerOptions from_config(const Config& cfg, const std::string& section);
};

}  // namespace vimot::frontend

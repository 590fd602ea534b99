#pragma once
// Up-to-scale 6-DoF object tracker: the object-region bundle adjustment of
// Qiu et al. (scale paper, Sec. III, Eq. 1-2, Fig. 5). No LCM here.
//
// Frames: C the monocular camera (cam0), O the object frame. The output
// R_OtoC = quat_to_rot(q_OtoC) maps vectors in O into C and pbar_OinC is the
// position of O in C in tracker units; the metric position is
// p_OinC = s * pbar_OinC with one unknown scale s per track.
//
// Gauge of a track (fixed at initialisation, Fig. 5):
//  * orientation of O = the camera orientation at the first frame of the
//    two-view initialisation (reference frame, utime reference_utime);
//  * origin of O = the point on the centre ray (unit bearing centre_ray_C0 in
//    that camera, through the 2D box centre) at distance d_ref from the
//    camera centre, where d_ref = median distance from the camera centre of
//    the `reference_features` reconstructed features whose bearings are
//    angularly nearest to the ray ("the surface along the ray");
//  * unit length = d_ref, so |pbar_OinC| = 1 at the reference frame.
// Hence s_true = median over reference_feature_ids of the true distances
// |p_FinC| at reference_utime (see InitFacts).
//
// Scale consistency: the two oldest window poses are held constant, and a
// pose that leaves the window is retired: constant, its views of the
// points (3D, in O) kept while those live; they carry the gauge forward. The
// window keeps keyframes (the newest-but-one frame is dropped unless it
// moved enough), so its N frames span more motion than N consecutive ones.
//
// Initialisation: every frame joins a buffer; with `init_frames` buffered,
// a two-view (essential matrix) between the first and the last gives
// depths, the frames in between are posed by PnP and all go through a BA. A
// small object projects almost affinely, so the depth-reversed structure is
// solved too; the tracker commits only if one is clearly cheaper
// (`init_min_chi2_gap`) and its points are not nearly planar
// (`init_min_thickness`: one face admits a family of structures), else the
// buffer slides on.
//
// Internally poses are Ceres parameter blocks (Eigen::Quaterniond, whose
// coefficient order x y z w is what EigenQuaternionManifold expects); they
// leave the class only as rotation matrices / JPL quaternions (quat.h).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/types/object_pose.h"
#include "common/types/sensor_data.h"

namespace vimot {

struct ObjectTrackerOptions {
  int window_size{20};                  // N frames in the sliding window (paper: 20)
  double focal_length_px{458.0};        // converts the pixel thresholds to normalized units
  std::string robust_loss{"huber"};     // huber | cauchy
  double robust_loss_px{1.5};           // px, scale of the robust loss
  int min_init_features{20};            // common target features needed to initialise
  double min_init_parallax_deg{2.0};    // median rotation-compensated parallax to initialise
  int init_frames{40};                  // consecutive frames the initialisation BA spans
  // The initialisation commits to one of the two (Necker) structures only if
  // the other's cost over the buffer is larger by this chi-square margin.
  double init_min_chi2_gap{25.0};
  // ... and only if its points are this far from one plane (smallest over
  // middle principal extent): the points of one face of a small object
  // admit a continuous family of structures, not just the reversed one.
  double init_min_thickness{0.2};
  double ransac_threshold_px{1.5};      // px, essential matrix and PnP RANSAC
  int reference_features{5};            // features nearest the centre ray that define depth 1
  int min_track_features{10};           // fewer BA features in a frame: track lost
  double max_reprojection_rms_px{3.0};  // larger RMS in a frame: track lost
  double outlier_threshold_px{3.0};     // observations beyond this are removed after the BA
  double min_feature_parallax_deg{3.0}; // a new feature joins the BA with this parallax ...
  int min_feature_observations{3};      // ... and this many observations
  int max_iterations{10};               // Ceres iterations per frame
  // The newest-but-one frame stays in the window (keyframe) if it moved this
  // much from the frame before it, else it is dropped; so the window spans
  // more relative motion than N consecutive frames.
  double keyframe_rotation_deg{3.0};
  double keyframe_baseline{0.05};       // tracker units (1 = the initial object distance)
  // A new feature id observed within this distance of the projection of
  // one BA point not seen in the frame (and no other within twice it) is
  // that point again (a broken track of the front end).
  double reassociation_px{4.0};
  // Retired poses kept (the newest); older ones are forgotten with their
  // views. Each retired pose adds its views of the living points to every
  // solve, so long tracks (from pixels) would grow the BA without bound.
  // 0 = no limit.
  int max_retired_poses{0};
};

/// Reads the `object_tracker:` section (every key optional, defaults above).
ObjectTrackerOptions object_tracker_options_from_config(const Config& config);

/// Optional 2D box of the object in pixels (e.g. TARGET_BOX).
struct BoundingBox2d {
  Eigen::Vector2d min_px{Eigen::Vector2d::Zero()};
  Eigen::Vector2d max_px{Eigen::Vector2d::Zero()};
};

/// What an evaluator needs to compute the true scale of a track.
struct InitFacts {
  int64_t track_id{0};
  int64_t reference_utime{0};  // µs, the frame that defines O
  int64_t init_utime{0};       // µs, the frame at which the two-view succeeded
  Eigen::Vector3d centre_ray_C0{Eigen::Vector3d::UnitZ()};  // unit bearing in the reference camera
  std::vector<int64_t> reference_feature_ids;               // their median distance is 1 unit
};

struct ObjectTrackerCounters {
  int64_t frames{0};
  int64_t rejected_time_backwards{0};
  int64_t rejected_duplicate_time{0};
  int64_t dropped_non_finite_observations{0};
  int64_t initialisations{0};
  int64_t track_losses{0};
  int64_t removed_outlier_observations{0};
};

class ObjectTracker {
 public:
  explicit ObjectTracker(ObjectTrackerOptions options = {});

  /// One camera frame (cam0 observations with is_target are used). A frame
  /// whose utime is not after the last accepted one is rejected (counted)
  /// and returns valid = false with that utime.
  ObjectPoseEstimate process(const CameraFrame& frame, const std::optional<BoundingBox2d>& box = std::nullopt);

  const ObjectTrackerCounters& counters() const { return counters_; }
  /// Facts of the current track; std::nullopt before the first initialisation.
  const std::optional<InitFacts>& init_facts() const { return init_facts_; }
  /// Wall time of the last frame's bundle adjustment (s).
  double last_solve_seconds() const { return last_solve_seconds_; }
  const ObjectTrackerOptions& options() const { return options_; }

 private:
  struct Pose {
    Eigen::Quaterniond q_OtoC{Eigen::Quaterniond::Identity()};  // R_OtoC
    Eigen::Vector3d pbar_OinC{Eigen::Vector3d::Zero()};
  };
  struct Feature {
    Eigen::Vector3d p_FinO{Eigen::Vector3d::Zero()};  // tracker units; set when it joins the BA
    std::map<int64_t, Eigen::Vector2d> observations;  // utime (window or retired pose) -> normalized
    bool in_ba{false};
  };
  using Observations = std::map<int64_t, Eigen::Vector2d>;  // feature id -> normalized
  struct InitFrame {
    int64_t utime{0};
    Observations observations;
    Eigen::Vector3d centre_ray{Eigen::Vector3d::UnitZ()};  // unit, this camera
  };

  ObjectPoseEstimate try_initialise(InitFrame frame);
  ObjectPoseEstimate track(int64_t utime, const Observations& raw_obs);
  Observations with_aliases(const Observations& obs) const;
  Observations associate(const Observations& raw_obs, const Pose& pose);
  Pose predict_pose(const Observations& obs) const;
  void add_observations(int64_t utime, const Observations& obs, const Pose& pose);
  bool solve_window(int num_fixed_poses, int max_iterations);
  int remove_outliers();
  void slide_window();
  bool is_keyframe(int64_t utime, int64_t previous_utime) const;
  void drop_frame(int64_t utime);
  void reset();
  double feature_parallax_rad(const Feature& f) const;
  double reprojection_error_px(const Feature& f, int64_t utime, const Eigen::Vector2d& z) const;
  ObjectPoseEstimate make_estimate(int64_t utime, const Observations& obs) const;

  ObjectTrackerOptions options_;
  ObjectTrackerCounters counters_;
  std::optional<int64_t> last_utime_;
  int64_t next_track_id_{1};
  std::optional<InitFacts> init_facts_;
  double last_solve_seconds_{0.0};

  bool tracking_{false};
  // Initialisation buffer: frames since the reference frame.
  std::deque<InitFrame> init_frames_;

  // Tracking state.
  std::deque<int64_t> window_;    // utimes, oldest first
  std::map<int64_t, Pose> poses_; // window and retired poses
  std::map<int64_t, Feature> features_;
  std::map<int64_t, int64_t> aliases_;  // front-end feature id -> the feature it continues
};

}  // namespace vimot

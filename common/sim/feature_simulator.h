#pragma once
// Camera measurement simulation: projects static map points and target face
// points into each camera, with visibility, occlusion, pixel noise, track
// loss and fresh track ids, as a real front end would deliver them.
//
// A point F is seen by camera C at a frame when
//   * its depth min_depth < z_C (<= max_depth if set), |p_FinC| <= max_range,
//   * pixel = distort(x/z, y/z) lies in the image (border margin),
//   * static points: the segment C→F does not cross the target box,
//   * target points: the face faces the camera, n_G·(p_C - p_F) > min_view_cos |p_C - p_F|
//     (back-face culling; the box is convex, so this is its self-occlusion).
// The measurement is pixel + N(0, σ² I₂) and normalized = undistort(that).
//
// Tracks: a point seen in a frame keeps its feature id from the previous
// frame; a point not seen in a frame loses its track; a tracked point is
// dropped with probability p per frame (not reported that frame). A point
// without a track gets a fresh id (one counter for all points) when seen.
// Stereo: one id per point, shared by the cameras that see it.
//
// Keep-N mode (OpenVINS's simulator): when a camera sees fewer than N static
// points, new static points are spawned at uniformly random pixels with a
// uniformly random depth in [spawn_depth_min, spawn_depth_max]; they join
// the map for good. A camera that sees more than N static points reports N:
// those tracked in the previous frame first, then the lowest landmark ids
// (OpenVINS keeps the first N of its map).
//
// Randomness: the map (static points, target points, spawned points) comes
// from the map seed; pixel noise and track loss from the noise seed, each
// in its own stream. Candidates are processed in landmark-id order, so the
// output is a function of the seeds and the poses only.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

#include "common/camera/camera_model.h"
#include "common/sim/sim_config.h"
#include "common/sim/sim_types.h"

namespace vimot {
namespace sim {

class FeatureSimulator {
 public:
  /// `workspace`: floor rectangle for MapConfig's floor and wall points
  /// (may be empty when the map counts are 0). `with_target`: create the
  /// target's face points.
  FeatureSimulator(const CameraSimConfig& camera, const MapConfig& map, const TargetConfig& target, bool with_target,
                   const Eigen::AlignedBox2d& workspace, uint64_t noise_seed, uint64_t map_seed);

  /// Observations of all cameras for the IMU pose T_ItoG and, when the
  /// target exists, its pose T_TtoG (nullptr otherwise).
  CameraFrame simulate(int64_t utime, const Eigen::Matrix4d& T_ItoG, const Eigen::Matrix4d* T_TtoG);

  /// All points so far (spawned ones appended); landmarks()[k].id == k.
  const std::vector<Landmark>& landmarks() const { return landmarks_; }
  const std::vector<CameraModel>& cameras() const { return cameras_; }

  /// The landmark a feature id was given to, or -1 for an unknown id.
  int64_t landmark_of_feature(int64_t feature_id) const;

  /// True if the segment from p_a to p_b (both in T) crosses the box of
  /// half extents `half_size` centred at T's origin (the end point itself
  /// excluded). Public for tests.
  static bool segment_hits_box(const Eigen::Vector3d& p_a, const Eigen::Vector3d& p_b,
                               const Eigen::Vector3d& half_size);

 private:
  struct CameraPose {
    Eigen::Matrix3d R_GtoC;
    Eigen::Vector3d p_CinG;
  };
  struct Visible {
    int64_t landmark;
    Eigen::Vector2d pixel;  // true (noise-free) pixel
  };

  // True pixel of p_FinG in camera `cam` if it passes the geometric checks.
  bool project(int cam, const CameraPose& pose, const Eigen::Vector3d& p_FinG, Eigen::Vector2d* pixel) const;
  bool static_visible(int cam, const CameraPose& pose, const Eigen::Vector3d& p_FinG, const Eigen::Matrix4d* T_TtoG,
                      Eigen::Vector2d* pixel) const;
  void add_static_point(const Eigen::Vector3d& p_FinG);
  std::vector<int64_t> static_candidates(const Eigen::Vector3d& center, double radius) const;
  int64_t cell_key(int ix, int iy, int iz) const;
  int cell_index(double x) const;
  void make_map(const MapConfig& map, const Eigen::AlignedBox2d& workspace);
  void make_target_points(const TargetConfig& target);

  CameraSimConfig config_;
  TargetConfig target_;
  bool with_target_{false};
  std::vector<CameraModel> cameras_;
  std::vector<Eigen::Vector3d> p_CinI_;          // camera centres in I
  std::vector<Eigen::AlignedBox2d> norm_bounds_; // normalized coordinates that can reach the image
  double max_p_CinI_{0.0};

  std::vector<Landmark> landmarks_;
  std::vector<int64_t> target_ids_;
  double cell_size_{1.0};
  std::unordered_map<int64_t, std::vector<int64_t>> grid_;  // static points by cell

  std::vector<int64_t> track_of_landmark_;  // active feature id, -1 if none
  std::vector<int64_t> active_;             // landmarks with an active track
  std::unordered_map<int64_t, int64_t> landmark_of_feature_;
  int64_t next_feature_id_{0};

  std::mt19937_64 map_rng_;
  std::mt19937_64 pixel_rng_;
  std::mt19937_64 track_rng_;
};

}  // namespace sim
}  // namespace vimot

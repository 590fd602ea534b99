#pragma once
// Rendered simulator: the grey images each camera of a Simulator sees, with
// the exact target mask and box, from the simulator's own truth.
//
// Scene: a closed room, an axis-aligned box over the simulator's workspace
// rectangle (the floor and wall area its static map points use), from the
// floor z = 0 up to map.wall_height, stretched to keep 1 m of clearance
// below and above the camera path (so no ray escapes: no sky, no void).
// Floor, walls and ceiling carry three different textures (render.*: a
// multi-scale pattern or a checkerboard) at render.texel_size per texel,
// each surface shaded by a constant factor. The target box of
// target.size (pose from Simulator::target_state) has its own texture, a
// different patch per face, Lambert-shaded under a fixed light.
//
// Image formation: every pixel is the scene along the ray of its centre,
// through the camera's exact lens model (CameraModel::undistort of the
// pixel, precomputed once), so a 3D point appears at
// CameraModel::distort(x/z, y/z) to within the Gauss-Newton tolerance. A
// texture is sampled trilinearly from its mip pyramid at the pixel's
// footprint on the surface (distance · pixel angle / sqrt(cos incidence)),
// so far surfaces are filtered rather than aliased. Then the exposure gain
// and white noise (render.noise_sigma) are applied and the value rounded to
// 8 bits. Pixels on the target's outline average 4 rays (anti-aliasing);
// elsewhere a pixel shows the surface its centre ray hits.
//
// Truth: mask(u, v) = 255 where the target is the nearest surface along the
// pixel's centre ray, else 0; box = [x_min, y_min, width, height] of the
// mask's pixels (width = columns spanned, as cv::boundingRect), all zero
// when the target is not visible.
//
// Determinism: textures come from map_seed, noise and the exposure phase
// from seed, the noise of an image from (seed, utime, camera) only, so
// render(utime) gives the same bytes whatever was rendered before.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "common/sim/simulator.h"
#include "common/sim/texture.h"

namespace vimot {
namespace sim {

/// One camera's image of one instant.
struct RenderedView {
  int camera_id{0};
  int64_t utime{0};
  cv::Mat image;  // CV_8UC1, the calibration's width x height, raw (distorted)
  cv::Mat mask;   // CV_8UC1, 255 where the target is the nearest surface
  bool visible{false};  // the mask has at least one pixel
  Eigen::Vector4d box{Eigen::Vector4d::Zero()};  // px, [x_min, y_min, width, height] of the mask
};

class Renderer {
 public:
  /// Keeps a reference to `sim` (which must outlive the renderer) for its
  /// truth; reads sim.config().render. Builds the textures and each camera's
  /// per-pixel rays (about a second). Throws std::invalid_argument when the
  /// room is empty or the camera path leaves it, std::runtime_error when a
  /// pixel cannot be undistorted.
  explicit Renderer(const Simulator& sim);
  // The faces point at the renderer's own textures.
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// The images of all cameras (index = camera_id) at `utime`, which must
  /// lie in [sim.start_utime(), sim.end_utime()] (std::invalid_argument).
  std::vector<RenderedView> render(int64_t utime) const;

  /// What pixel `pixel` (raw, distorted; pixel centres at integer
  /// coordinates, as rendered) of camera `cam` sees at `utime`: the nearest
  /// surface along its ray, in double precision — the geometry the image
  /// shows, for checking a tracker against truth. std::invalid_argument for
  /// a bad camera or utime, std::runtime_error for a pixel that cannot be
  /// undistorted.
  struct SurfaceHit {
    Eigen::Vector3d p_inG{Eigen::Vector3d::Zero()};  // the hit point (m)
    bool on_target{false};                           // the target, not the room
  };
  SurfaceHit surface_at(int cam, int64_t utime, const Eigen::Vector2d& pixel) const;

  /// The room's bounds in G (m).
  const Eigen::AlignedBox3d& room() const { return room_; }

 private:
  // Per pixel, row-major (arrays, so the per-row geometry vectorizes): the
  // normalized (undistorted) ray (x, y, 1), 1 / its norm, and the pixel's
  // angular size (rad, square root of its solid angle) times the norm.
  struct CameraRays {
    int width{0}, height{0};
    std::vector<float> x, y, inv_norm, angle_norm;
  };
  struct Face {
    const MipTexture* texture{nullptr};
    float shade{1.0f};
  };

  void build_rays(const CameraModel& model);
  void build_textures();
  RenderedView render_camera(int cam, int64_t utime, const Eigen::Matrix4d& T_ItoG, const Eigen::Matrix4d* T_TtoG,
                             double gain) const;

  const Simulator& sim_;
  RenderConfig config_;
  Eigen::AlignedBox3d room_;
  Eigen::Vector3d target_half_{Eigen::Vector3d::Zero()};
  std::vector<CameraRays> cameras_;
  MipTexture floor_, wall_, ceiling_, target_;
  // Room faces: 0/1 x min/max, 2/3 y min/max, 4 floor, 5 ceiling.
  std::array<Face, 6> room_faces_;
  float target_texel_{0.0f};  // m per target texel
  int target_cell_{0};        // texels per target face cell
  double exposure_phase_{0.0};
  uint64_t noise_seed_{0};
};

}  // namespace sim
}  // namespace vimot

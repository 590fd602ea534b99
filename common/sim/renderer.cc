#include "common/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

namespace vimot {
namespace sim {

namespace {

// Random streams (see derive_seed): textures from map_seed, the rest from seed.
constexpr uint64_t kStreamFloorTexture = 21;
constexpr uint64_t kStreamWallTexture = 22;
constexpr uint64_t kStreamCeilingTexture = 23;
constexpr uint64_t kStreamTargetTexture = 24;
constexpr uint64_t kStreamImageNoise = 25;
constexpr uint64_t kStreamExposure = 26;

// Clearance (m) the room keeps below and above the camera path, and the
// spacing (s) at which the path is sampled to check it.
constexpr double kRoomClearance = 1.0;
constexpr double kPathSampleDt = 0.1;

// Constant shading of the room's surfaces (x walls, y walls, floor,
// ceiling): neighbouring surfaces differ, as under real lighting.
constexpr float kShadeWallX = 0.9f;
constexpr float kShadeWallY = 0.8f;
constexpr float kShadeFloor = 1.0f;
constexpr float kShadeCeiling = 0.75f;
// Target faces: ambient (render.target_ambient) + Lambert term under a
// fixed light from above.
const Eigen::Vector3d kLightDirG = Eigen::Vector3d(0.3, 0.5, 0.8).normalized();

// The target texture: a pattern with stronger contrast than the scene's and
// a different scale range, so its features describe it rather than the room.
PatternStyle target_style(int cell) {
  PatternStyle style;
  style.min_size = 3.0;
  style.max_size = 0.5 * cell;
  style.contrast = 70.0;
  style.coverage = 0.45;
  return style;
}

// Cells of the target texture: 4 x 2, one per face (4 x 2 >= 6).
constexpr int kTargetCellsX = 4;
constexpr int kTargetCellsY = 2;

std::string fmt(double v) {
  std::ostringstream ss;
  ss.precision(6);
  ss << v;
  return ss.str();
}

Eigen::Vector3d camera_centre(const Eigen::Matrix4d& T_ItoG, const CameraCalibration& calib) {
  const Eigen::Vector3d p_CinI = -calib.R_ItoC.transpose() * calib.p_IinC;
  return T_ItoG.topLeftCorner<3, 3>() * p_CinI + T_ItoG.topRightCorner<3, 1>();
}

Eigen::Matrix4d pose_of(const SplineState& state) { return make_se3(state.R_BtoG, state.p_BinG); }

// log2 of a positive, finite x to about 0.005: exponent plus a quadratic in
// the mantissa. Only picks mip levels, several times cheaper than std::log2.
inline float fast_log2(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const float exponent = static_cast<float>(static_cast<int>(bits >> 23) - 127);
  bits = (bits & 0x007FFFFFu) | 0x3F800000u;
  float m;  // mantissa in [1, 2)
  std::memcpy(&m, &bits, sizeof m);
  return exponent + (-0.34484843f * m + 2.02466578f) * m - 0.67487759f;
}

// Mip level of a pixel whose centre ray meets a surface at camera depth t:
// footprint = distance · pixel angle / sqrt(cos incidence), in texels.
// `angle_norm` = pixel angle · |ray|, `cos_num` = |ray · normal| (so
// cos incidence = cos_num · inv_norm). Squared, so there is no sqrt.
inline float mip_level(float t, float angle_norm, float inv_norm, float cos_num, float inv_texel) {
  const float f = t * angle_norm * inv_texel;
  return 0.5f * fast_log2(f * f / (cos_num * inv_norm));
}

// The camera's view of the room for one frame: R_CtoG (row-major), the
// offsets from the camera to the lower / upper walls per axis, the texture
// coordinate of the camera centre per axis, 1 / texel size.
struct RoomView {
  float R[9];
  float lo[3], hi[3];
  float origin_tex[3];
  float inv_texel;
};

// For one image row: where each pixel's ray leaves the room (camera depth
// t), on which face (2 axis + (upper wall)), the texture coordinates there
// and the mip level. Branch-free so it vectorizes (see CMakeLists.txt).
void room_row(const RoomView& view, std::size_t width, const float* __restrict xs, const float* __restrict ys,
              const float* __restrict inv_norms, const float* __restrict angle_norms, float* __restrict ss,
              float* __restrict ts, float* __restrict lods, float* __restrict t_rooms, int* __restrict faces) {
  const float r00 = view.R[0], r01 = view.R[1], r02 = view.R[2], r10 = view.R[3], r11 = view.R[4], r12 = view.R[5],
              r20 = view.R[6], r21 = view.R[7], r22 = view.R[8];
  const float lo0 = view.lo[0], lo1 = view.lo[1], lo2 = view.lo[2], hi0 = view.hi[0], hi1 = view.hi[1],
              hi2 = view.hi[2];
  const float o0 = view.origin_tex[0], o1 = view.origin_tex[1], o2 = view.origin_tex[2];
  const float inv_texel_f = view.inv_texel;
  for (std::size_t u = 0; u < width; ++u) {
    const float rx = xs[u], ry = ys[u];
    // Ray direction in G, parametrised by camera depth (camera z = 1).
    const float d0 = r00 * rx + r01 * ry + r02, d1 = r10 * rx + r11 * ry + r12, d2 = r20 * rx + r21 * ry + r22;
    // The room seen from inside: wall k is num_k / |d_k| away (num_k >=
    // 0); pick the nearest by cross-multiplying, divide once.
    const float n0 = d0 > 0.0f ? hi0 : -lo0, n1 = d1 > 0.0f ? hi1 : -lo1, n2 = d2 > 0.0f ? hi2 : -lo2;
    const float a0 = std::abs(d0), a1 = std::abs(d1), a2 = std::abs(d2);
    const bool y_wall = n1 * a0 < n0 * a1;
    float num = y_wall ? n1 : n0, den = y_wall ? a1 : a0, d_axis = y_wall ? d1 : d0;
    const bool z_wall = n2 * den < num * a2;
    num = z_wall ? n2 : num;
    den = z_wall ? a2 : den;
    d_axis = z_wall ? d2 : d_axis;
    const float t = num / den;
    // Texture coordinates: the two world axes along the wall hit.
    const float w0 = o0 + t * d0 * inv_texel_f, w1 = o1 + t * d1 * inv_texel_f, w2 = o2 + t * d2 * inv_texel_f;
    const bool x_wall = !(y_wall | z_wall);
    ss[u] = x_wall ? w1 : w0;
    ts[u] = z_wall ? w1 : w2;
    lods[u] = mip_level(t, angle_norms[u], inv_norms[u], den, inv_texel_f);
    t_rooms[u] = t;
    faces[u] = 2 * (z_wall ? 2 : (y_wall ? 1 : 0)) + (d_axis > 0.0f ? 1 : 0);
  }
}

}  // namespace

Renderer::Renderer(const Simulator& sim) : sim_(sim), config_(sim.config().render) {
  validate(sim.config());
  const SimConfig& sc = sim.config();
  const Eigen::AlignedBox2d& ws = sim.workspace();
  if (ws.isEmpty() || !(ws.sizes().minCoeff() > 0.0)) {
    throw std::invalid_argument("Renderer: the scenario's workspace (the room's floor) is empty");
  }
  // Room height: the static map's walls, grown to keep clearance around the path.
  double z_lo = 0.0, z_hi = sc.map.wall_height;
  const int n = std::max(2, static_cast<int>(std::ceil(sim.duration() / kPathSampleDt)) + 1);
  for (int k = 0; k < n; ++k) {
    const double t = sim.duration() * static_cast<double>(k) / static_cast<double>(n - 1);
    const Eigen::Matrix4d T_ItoG = pose_of(sim.robot_state(t));
    for (const CameraCalibration& calib : sim.cameras()) {
      const Eigen::Vector3d p = camera_centre(T_ItoG, calib);
      if (!ws.contains(Eigen::Vector2d(p.head<2>()))) {
        throw std::invalid_argument("Renderer: camera at (" + fmt(p.x()) + ", " + fmt(p.y()) + ") m at t = " +
                                    fmt(t) + " s leaves the room (the workspace rectangle); grow map.margin or "
                                    "the mono room");
      }
      z_lo = std::min(z_lo, p.z() - kRoomClearance);
      z_hi = std::max(z_hi, p.z() + kRoomClearance);
    }
  }
  room_ = Eigen::AlignedBox3d(Eigen::Vector3d(ws.min().x(), ws.min().y(), z_lo),
                              Eigen::Vector3d(ws.max().x(), ws.max().y(), z_hi));
  if (sim.has_target()) target_half_ = 0.5 * sc.target.size;

  build_textures();
  for (const CameraModel& model : sim.camera_models()) build_rays(model);
  std::mt19937_64 rng(derive_seed(sc.seed, kStreamExposure));
  exposure_phase_ = 2.0 * M_PI * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  noise_seed_ = derive_seed(sc.seed, kStreamImageNoise);
}

void Renderer::build_textures() {
  const uint64_t map_seed = sim_.config().map_seed;
  const int size = config_.texture_size;
  auto scene = [&](uint64_t stream) {
    if (config_.scene_texture == SurfaceTexture::kCheckerboard) {
      return make_checkerboard_texture(size, size,
                                       static_cast<int>(std::lround(config_.checker_square / config_.texel_size)));
    }
    return make_pattern_texture(size, size, PatternStyle(), derive_seed(map_seed, stream));
  };
  floor_ = MipTexture(scene(kStreamFloorTexture));
  wall_ = MipTexture(scene(kStreamWallTexture));
  ceiling_ = MipTexture(scene(kStreamCeilingTexture));
  room_faces_ = {Face{&wall_, kShadeWallX},  Face{&wall_, kShadeWallX},   Face{&wall_, kShadeWallY},
                 Face{&wall_, kShadeWallY},  Face{&floor_, kShadeFloor}, Face{&ceiling_, kShadeCeiling}};

  if (!sim_.has_target()) return;
  target_cell_ = config_.target_texture_size;
  target_texel_ = static_cast<float>(sim_.config().target.size.maxCoeff() / target_cell_);
  if (config_.target_texture == SurfaceTexture::kCheckerboard) {
    // Squares start at each face's corner: one checkerboard per cell.
    const cv::Mat cell = make_checkerboard_texture(
        target_cell_, target_cell_, static_cast<int>(std::lround(config_.checker_square / target_texel_)));
    cv::Mat atlas(kTargetCellsY * target_cell_, kTargetCellsX * target_cell_, CV_8UC1);
    for (int cy = 0; cy < kTargetCellsY; ++cy) {
      for (int cx = 0; cx < kTargetCellsX; ++cx) {
        cell.copyTo(atlas(cv::Rect(cx * target_cell_, cy * target_cell_, target_cell_, target_cell_)));
      }
    }
    target_ = MipTexture(atlas);
  } else {
    target_ = MipTexture(make_pattern_texture(kTargetCellsX * target_cell_, kTargetCellsY * target_cell_,
                                              target_style(target_cell_),
                                              derive_seed(map_seed, kStreamTargetTexture)));
  }
}

void Renderer::build_rays(const CameraModel& model) {
  const CameraCalibration& calib = model.calibration();
  CameraRays cam;
  cam.width = calib.width;
  cam.height = calib.height;
  const std::size_t count = static_cast<std::size_t>(cam.width) * static_cast<std::size_t>(cam.height);
  cam.x.resize(count);
  cam.y.resize(count);
  cam.inv_norm.resize(count);
  cam.angle_norm.resize(count);
  std::vector<Eigen::Vector3d> unit(count);
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      Eigen::Vector2d n;
      try {
        n = model.undistort(Eigen::Vector2d(u, v));
      } catch (const std::runtime_error& e) {
        throw std::runtime_error("Renderer: camera " + std::to_string(cameras_.size()) + " cannot undistort pixel (" +
                                 std::to_string(u) + ", " + std::to_string(v) + "): " + e.what() +
                                 "; check its distortion coefficients");
      }
      const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(cam.width) + static_cast<std::size_t>(u);
      const Eigen::Vector3d r(n.x(), n.y(), 1.0);
      unit[i] = r.normalized();
      cam.x[i] = static_cast<float>(n.x());
      cam.y[i] = static_cast<float>(n.y());
      cam.inv_norm[i] = static_cast<float>(1.0 / r.norm());
    }
  }
  // Angular size: square root of the solid angle the pixel spans, from the
  // differences of neighbouring rays (central inside, one-sided at the border).
  auto at = [&](int u, int v) -> const Eigen::Vector3d& {
    return unit[static_cast<std::size_t>(v) * static_cast<std::size_t>(cam.width) + static_cast<std::size_t>(u)];
  };
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const int u0 = std::max(u - 1, 0), u1 = std::min(u + 1, cam.width - 1);
      const int v0 = std::max(v - 1, 0), v1 = std::min(v + 1, cam.height - 1);
      const Eigen::Vector3d du = (at(u1, v) - at(u0, v)) / static_cast<double>(u1 - u0);
      const Eigen::Vector3d dv = (at(u, v1) - at(u, v0)) / static_cast<double>(v1 - v0);
      const std::size_t i = static_cast<std::size_t>(v) * static_cast<std::size_t>(cam.width) + static_cast<std::size_t>(u);
      cam.angle_norm[i] = static_cast<float>(std::sqrt(du.cross(dv).norm())) / cam.inv_norm[i];
    }
  }
  cameras_.push_back(std::move(cam));
}

std::vector<RenderedView> Renderer::render(int64_t utime) const {
  if (utime < sim_.start_utime() || utime > sim_.end_utime()) {
    throw std::invalid_argument("Renderer::render: utime " + std::to_string(utime) + " outside the run [" +
                                std::to_string(sim_.start_utime()) + ", " + std::to_string(sim_.end_utime()) + "]");
  }
  const double t = sim_.sim_time(utime);
  const Eigen::Matrix4d T_ItoG = pose_of(sim_.robot_state(t));
  const std::optional<SplineState> target = sim_.target_state(t);
  const Eigen::Matrix4d T_TtoG = target ? pose_of(*target) : Eigen::Matrix4d::Identity();
  const double gain = std::exp(config_.exposure_amplitude *
                               std::sin(2.0 * M_PI * config_.exposure_frequency_hz * t + exposure_phase_));
  std::vector<RenderedView> views;
  for (int cam = 0; cam < static_cast<int>(cameras_.size()); ++cam) {
    views.push_back(render_camera(cam, utime, T_ItoG, target ? &T_TtoG : nullptr, gain));
  }
  return views;
}

Renderer::SurfaceHit Renderer::surface_at(int cam, int64_t utime, const Eigen::Vector2d& pixel) const {
  if (cam < 0 || cam >= static_cast<int>(cameras_.size())) {
    throw std::invalid_argument("Renderer::surface_at: no camera " + std::to_string(cam));
  }
  if (utime < sim_.start_utime() || utime > sim_.end_utime()) {
    throw std::invalid_argument("Renderer::surface_at: utime " + std::to_string(utime) + " outside the run");
  }
  const double t = sim_.sim_time(utime);
  const CameraCalibration& calib = sim_.cameras()[static_cast<std::size_t>(cam)];
  const Eigen::Matrix4d T_ItoG = pose_of(sim_.robot_state(t));
  const Eigen::Matrix3d R_CtoG = T_ItoG.topLeftCorner<3, 3>() * calib.R_ItoC.transpose();
  const Eigen::Vector3d o = camera_centre(T_ItoG, calib);
  const Eigen::Vector2d n = sim_.camera_models()[static_cast<std::size_t>(cam)].undistort(pixel);
  const Eigen::Vector3d d = R_CtoG * Eigen::Vector3d(n.x(), n.y(), 1.0);
  // The room seen from inside: the nearest wall the ray leaves through.
  double t_hit = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    if (d(k) != 0.0) t_hit = std::min(t_hit, ((d(k) > 0.0 ? room_.max()(k) : room_.min()(k)) - o(k)) / d(k));
  }
  SurfaceHit hit;
  const std::optional<SplineState> target = sim_.target_state(t);
  if (target) {
    // Slab test in the target's frame.
    const Eigen::Vector3d o_T = target->R_BtoG.transpose() * (o - target->p_BinG);
    const Eigen::Vector3d d_T = target->R_BtoG.transpose() * d;
    double t_in = 0.0, t_out = t_hit;
    for (int k = 0; k < 3; ++k) {
      if (d_T(k) == 0.0) {
        if (std::abs(o_T(k)) > target_half_(k)) t_in = t_out + 1.0;
        continue;
      }
      double t1 = (-target_half_(k) - o_T(k)) / d_T(k), t2 = (target_half_(k) - o_T(k)) / d_T(k);
      if (t1 > t2) std::swap(t1, t2);
      t_in = std::max(t_in, t1);
      t_out = std::min(t_out, t2);
    }
    if (t_in <= t_out && t_in > 0.0) {
      t_hit = t_in;
      hit.on_target = true;
    }
  }
  hit.p_inG = o + t_hit * d;
  return hit;
}

RenderedView Renderer::render_camera(int cam, int64_t utime, const Eigen::Matrix4d& T_ItoG,
                                     const Eigen::Matrix4d* T_TtoG, double gain) const {
  const CameraCalibration& calib = sim_.cameras()[static_cast<std::size_t>(cam)];
  const CameraRays& rays = cameras_[static_cast<std::size_t>(cam)];
  const Eigen::Matrix3d R_CtoG = T_ItoG.topLeftCorner<3, 3>() * calib.R_ItoC.transpose();
  const Eigen::Vector3d p_CinG = camera_centre(T_ItoG, calib);
  if (!room_.contains(p_CinG)) {
    throw std::runtime_error("Renderer: camera " + std::to_string(cam) + " is outside the room at utime " +
                             std::to_string(utime));
  }
  // The room from this camera. Texture coordinates count from the last
  // whole texture period below the room: every hit point then has a
  // coordinate >= -0.5 (what MipTexture::sample needs), small enough for
  // float precision, and the textures stay aligned to the world axes.
  RoomView room;
  const double period = config_.texture_size * config_.texel_size;
  for (int k = 0; k < 3; ++k) {
    room.lo[k] = static_cast<float>(room_.min()(k) - p_CinG(k));
    room.hi[k] = static_cast<float>(room_.max()(k) - p_CinG(k));
    const double base = std::floor(room_.min()(k) / period) * period;
    room.origin_tex[k] = static_cast<float>((p_CinG(k) - base) / config_.texel_size - 0.5);
  }
  for (int k = 0; k < 9; ++k) room.R[k] = static_cast<float>(R_CtoG(k / 3, k % 3));
  room.inv_texel = static_cast<float>(1.0 / config_.texel_size);

  // Target in the camera frame: rays in T, and the box of normalized
  // coordinates its projection can cover (all rays tested when it straddles
  // the camera plane, none when it is behind).
  Eigen::Matrix3f R_CtoT = Eigen::Matrix3f::Identity();
  Eigen::Vector3f o_T = Eigen::Vector3f::Zero();
  Eigen::Vector3f half = target_half_.cast<float>();
  float face_shade[3][2] = {};  // [axis][0: + face, 1: - face]
  float bx0 = 1.0f, bx1 = -1.0f, by0 = 1.0f, by1 = -1.0f;  // empty
  if (T_TtoG != nullptr) {
    const Eigen::Matrix3d R_TtoG = T_TtoG->topLeftCorner<3, 3>();
    const Eigen::Vector3d p_TinG = T_TtoG->topRightCorner<3, 1>();
    R_CtoT = (R_TtoG.transpose() * R_CtoG).cast<float>();
    o_T = (R_TtoG.transpose() * (p_CinG - p_TinG)).cast<float>();
    for (int k = 0; k < 3; ++k) {
      const double lambert = std::max(0.0, R_TtoG.col(k).dot(kLightDirG));
      const double lambert_neg = std::max(0.0, -R_TtoG.col(k).dot(kLightDirG));
      const double ambient = config_.target_ambient;
      face_shade[k][0] = static_cast<float>(ambient + (1.0 - ambient) * lambert);
      face_shade[k][1] = static_cast<float>(ambient + (1.0 - ambient) * lambert_neg);
    }
    const Eigen::Matrix3d R_GtoC = R_CtoG.transpose();
    int in_front = 0;
    float x0 = std::numeric_limits<float>::max(), x1 = -x0, y0 = x0, y1 = -x0;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner(c & 1 ? target_half_.x() : -target_half_.x(),
                                   c & 2 ? target_half_.y() : -target_half_.y(),
                                   c & 4 ? target_half_.z() : -target_half_.z());
      const Eigen::Vector3d p = R_GtoC * (R_TtoG * corner + p_TinG - p_CinG);
      if (p.z() > 1e-6) {
        ++in_front;
        x0 = std::min(x0, static_cast<float>(p.x() / p.z()));
        x1 = std::max(x1, static_cast<float>(p.x() / p.z()));
        y0 = std::min(y0, static_cast<float>(p.y() / p.z()));
        y1 = std::max(y1, static_cast<float>(p.y() / p.z()));
      }
    }
    if (in_front == 8) {
      bx0 = x0, bx1 = x1, by0 = y0, by1 = y1;
    } else if (in_front > 0) {
      bx0 = by0 = -std::numeric_limits<float>::infinity();
      bx1 = by1 = std::numeric_limits<float>::infinity();
    }
  }
  const float target_inv_texel = target_texel_ > 0.0f ? 1.0f / target_texel_ : 0.0f;
  const float cell = static_cast<float>(target_cell_);

  // Radiance of the target along ray (rx, ry, 1) (inside the target's box
  // of rays) if it is nearer than t_room (camera depth): slab test in T,
  // then the face's texture.
  auto in_target_box = [&](float rx, float ry) { return rx >= bx0 && rx <= bx1 && ry >= by0 && ry <= by1; };
  auto shade_target = [&](float rx, float ry, float inv_norm, float angle_norm, float t_room, float* value) {
    const float dt[3] = {R_CtoT(0, 0) * rx + R_CtoT(0, 1) * ry + R_CtoT(0, 2),
                         R_CtoT(1, 0) * rx + R_CtoT(1, 1) * ry + R_CtoT(1, 2),
                         R_CtoT(2, 0) * rx + R_CtoT(2, 1) * ry + R_CtoT(2, 2)};
    float t_in = 0.0f, t_out = t_room;
    int face_axis = -1;
    for (int k = 0; k < 3 && t_in <= t_out; ++k) {
      const float inv = 1.0f / dt[k];  // ±inf for a ray parallel to the slab
      float t1 = (-half(k) - o_T(k)) * inv, t2 = (half(k) - o_T(k)) * inv;
      if (t1 > t2) std::swap(t1, t2);
      if (!(t2 >= t1)) t1 = t2 = std::numeric_limits<float>::infinity();  // NaN: on the slab plane
      if (t1 > t_in) t_in = t1, face_axis = k;
      t_out = std::min(t_out, t2);
    }
    if (face_axis < 0 || t_in > t_out) return false;
    // Entered through face (face_axis, side): side 0 is the + face.
    const int side = dt[face_axis] < 0.0f ? 0 : 1;
    const int face = 2 * face_axis + side;
    const int a1 = (face_axis + 1) % 3, a2 = (face_axis + 2) % 3;
    const float cx = static_cast<float>((face % kTargetCellsX) * target_cell_);
    const float cy = static_cast<float>((face / kTargetCellsX) * target_cell_);
    const float p1 = o_T(a1) + t_in * dt[a1] + half(a1), p2 = o_T(a2) + t_in * dt[a2] + half(a2);
    const float s = std::clamp(p1 * target_inv_texel - 0.5f, 0.0f, cell - 1.0f) + cx;
    const float tt = std::clamp(p2 * target_inv_texel - 0.5f, 0.0f, cell - 1.0f) + cy;
    const float lod = mip_level(t_in, angle_norm, inv_norm, std::abs(dt[face_axis]), target_inv_texel);
    *value = face_shade[face_axis][side] * target_.sample(s, tt, lod);
    return true;
  };
  auto shade_room = [this](int face_index, float s, float t, float lod) {
    const Face& face = room_faces_[static_cast<std::size_t>(face_index)];
    return face.shade * face.texture->sample(s, t, lod);
  };

  RenderedView view;
  view.camera_id = cam;
  view.utime = utime;
  cv::Mat radiance(rays.height, rays.width, CV_32FC1);
  view.mask = cv::Mat::zeros(rays.height, rays.width, CV_8UC1);
  int mu0 = rays.width, mu1 = -1, mv0 = rays.height, mv1 = -1;

  // Per row: the room hit of every pixel (branch-free, vectorizable), then
  // the target where its box of rays is, then the texture lookups.
  const std::size_t width = static_cast<std::size_t>(rays.width);
  std::vector<float> tex_s(width), tex_t(width), tex_lod(width), t_room(width);
  std::vector<int> room_face(width);
  for (int v = 0; v < rays.height; ++v) {
    const std::size_t row = static_cast<std::size_t>(v) * width;
    const float* xs = rays.x.data() + row;
    const float* ys = rays.y.data() + row;
    const float* inv_norms = rays.inv_norm.data() + row;
    const float* angle_norms = rays.angle_norm.data() + row;
    room_row(room, width, xs, ys, inv_norms, angle_norms, tex_s.data(), tex_t.data(), tex_lod.data(), t_room.data(),
             room_face.data());
    float* out = radiance.ptr<float>(v);
    uint8_t* mask = view.mask.ptr<uint8_t>(v);
    for (std::size_t i = 0; i < width; ++i) {
      if (in_target_box(xs[i], ys[i]) && shade_target(xs[i], ys[i], inv_norms[i], angle_norms[i], t_room[i], &out[i])) {
        const int u = static_cast<int>(i);
        mask[i] = 255;
        mu0 = std::min(mu0, u), mu1 = std::max(mu1, u);
        mv0 = std::min(mv0, v), mv1 = std::max(mv1, v);
      } else {
        out[i] = shade_room(room_face[i], tex_s[i], tex_t[i], tex_lod[i]);
      }
    }
  }

  // Anti-aliased silhouette: a pixel on the mask's edge (a 4-neighbour on
  // the other side) averages 4 rays at (±1/4, ±1/4) px, their directions
  // from the rays' local derivatives, so the target's outline blends with
  // the background as a camera's pixel area would. The mask keeps the
  // centre ray's answer.
  constexpr int kSubSamples = 4;
  constexpr float kOffsets[kSubSamples][2] = {{-0.25f, -0.25f}, {0.25f, -0.25f}, {-0.25f, 0.25f}, {0.25f, 0.25f}};
  for (int v = std::max(mv0 - 1, 0); v <= std::min(mv1 + 1, rays.height - 1); ++v) {
    for (int u = std::max(mu0 - 1, 0); u <= std::min(mu1 + 1, rays.width - 1); ++u) {
      const uint8_t m = view.mask.at<uint8_t>(v, u);
      const int u0 = std::max(u - 1, 0), u1 = std::min(u + 1, rays.width - 1);
      const int v0 = std::max(v - 1, 0), v1 = std::min(v + 1, rays.height - 1);
      if (view.mask.at<uint8_t>(v, u0) == m && view.mask.at<uint8_t>(v, u1) == m &&
          view.mask.at<uint8_t>(v0, u) == m && view.mask.at<uint8_t>(v1, u) == m) {
        continue;
      }
      auto at = [&](const std::vector<float>& a, int uu, int vv) {
        return a[static_cast<std::size_t>(vv) * width + static_cast<std::size_t>(uu)];
      };
      const float du = 1.0f / static_cast<float>(u1 - u0), dv = 1.0f / static_cast<float>(v1 - v0);
      const float x_u = (at(rays.x, u1, v) - at(rays.x, u0, v)) * du, x_v = (at(rays.x, u, v1) - at(rays.x, u, v0)) * dv;
      const float y_u = (at(rays.y, u1, v) - at(rays.y, u0, v)) * du, y_v = (at(rays.y, u, v1) - at(rays.y, u, v0)) * dv;
      float sx[kSubSamples], sy[kSubSamples], sn[kSubSamples], sa[kSubSamples];
      for (int k = 0; k < kSubSamples; ++k) {
        sx[k] = at(rays.x, u, v) + kOffsets[k][0] * x_u + kOffsets[k][1] * x_v;
        sy[k] = at(rays.y, u, v) + kOffsets[k][0] * y_u + kOffsets[k][1] * y_v;
        sn[k] = 1.0f / std::sqrt(sx[k] * sx[k] + sy[k] * sy[k] + 1.0f);
        sa[k] = at(rays.angle_norm, u, v);
      }
      float ss[kSubSamples], st[kSubSamples], slod[kSubSamples], st_room[kSubSamples];
      int sface[kSubSamples];
      room_row(room, kSubSamples, sx, sy, sn, sa, ss, st, slod, st_room, sface);
      float sum = 0.0f;
      for (int k = 0; k < kSubSamples; ++k) {
        float value = 0.0f;
        if (!(in_target_box(sx[k], sy[k]) && shade_target(sx[k], sy[k], sn[k], sa[k], st_room[k], &value))) {
          value = shade_room(sface[k], ss[k], st[k], slod[k]);
        }
        sum += value;
      }
      radiance.at<float>(v, u) = sum / kSubSamples;
    }
  }

  // Exposure gain, then noise; rounded and saturated to 8 bits.
  if (config_.noise_sigma > 0.0) {
    cv::RNG rng(derive_seed(noise_seed_ ^ static_cast<uint64_t>(utime), static_cast<uint64_t>(cam)));
    cv::Mat noise(radiance.size(), CV_32FC1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, config_.noise_sigma);
    cv::scaleAdd(radiance, gain, noise, radiance);
    radiance.convertTo(view.image, CV_8U);
  } else {
    radiance.convertTo(view.image, CV_8U, gain);
  }
  view.visible = mu1 >= 0;
  if (view.visible) view.box = Eigen::Vector4d(mu0, mv0, mu1 - mu0 + 1, mv1 - mv0 + 1);
  return view;
}

}  // namespace sim
}  // namespace vimot

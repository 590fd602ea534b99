#include "common/sim/feature_simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace vimot {
namespace sim {

namespace {

// Random streams derived from the seeds (see derive_seed).
constexpr uint64_t kStreamMap = 11;
constexpr uint64_t kStreamPixel = 12;
constexpr uint64_t kStreamTrack = 13;

// Border pixels sampled (per edge) to bound the normalized coordinates that
// can land in the image, and the relative growth of that box. Points outside
// it are rejected before distort(), whose polynomial can fold far-away rays
// back into the image.
constexpr int kBorderSamples = 32;
constexpr double kNormBoundsGrowth = 0.25;

// Bits per grid axis in the cell key (cells are offset to be non-negative).
constexpr int kCellBits = 21;
constexpr int64_t kCellOffset = int64_t{1} << (kCellBits - 1);

}  // namespace

FeatureSimulator::FeatureSimulator(const CameraSimConfig& camera, const MapConfig& map, const TargetConfig& target,
                                   bool with_target, const Eigen::AlignedBox2d& workspace, uint64_t noise_seed,
                                   uint64_t map_seed)
    : config_(camera),
      target_(target),
      with_target_(with_target),
      map_rng_(derive_seed(map_seed, kStreamMap)),
      pixel_rng_(derive_seed(noise_seed, kStreamPixel)),
      track_rng_(derive_seed(noise_seed, kStreamTrack)) {
  for (const CameraCalibration& calib : camera.calibrations) {
    cameras_.emplace_back(calib);
    const CameraModel& model = cameras_.back();
    p_CinI_.push_back(-calib.R_ItoC.transpose() * calib.p_IinC);
    max_p_CinI_ = std::max(max_p_CinI_, p_CinI_.back().norm());
    Eigen::AlignedBox2d box;
    const double w = calib.width - 1.0, h = calib.height - 1.0;
    auto extend = [&box, &model](const Eigen::Vector2d& px) {
      // A border pixel beyond the lens model's fold has no ray: skip it.
      try {
        box.extend(model.undistort(px));
      } catch (const std::runtime_error&) {
      }
    };
    for (int k = 0; k <= kBorderSamples; ++k) {
      const double s = static_cast<double>(k) / kBorderSamples;
      extend(Eigen::Vector2d(s * w, 0.0));
      extend(Eigen::Vector2d(s * w, h));
      extend(Eigen::Vector2d(0.0, s * h));
      extend(Eigen::Vector2d(w, s * h));
    }
    if (box.isEmpty()) {
      throw std::invalid_argument("FeatureSimulator: camera " + std::to_string(cameras_.size() - 1) +
                                  " cannot undistort any border pixel; check its distortion coefficients");
    }
    const Eigen::Vector2d grow = kNormBoundsGrowth * box.sizes();
    box.min() -= grow;
    box.max() += grow;
    norm_bounds_.push_back(box);
  }
  // Query cubes of a few cells per axis around the camera.
  cell_size_ = std::max(1.0, camera.max_range / 4.0);
  make_map(map, workspace);
  if (with_target_) make_target_points(target);
}

void FeatureSimulator::make_map(const MapConfig& map, const Eigen::AlignedBox2d& workspace) {
  if (map.floor_points + map.wall_points == 0) return;
  const Eigen::Vector2d lo = workspace.min(), size = workspace.sizes();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int k = 0; k < map.floor_points; ++k) {
    const double x = lo.x() + size.x() * unit(map_rng_);
    const double y = lo.y() + size.y() * unit(map_rng_);
    add_static_point(Eigen::Vector3d(x, y, 0.0));
  }
  // Walls: uniform along the perimeter (counter-clockwise from min corner).
  const double perimeter = 2.0 * (size.x() + size.y());
  for (int k = 0; k < map.wall_points; ++k) {
    double s = perimeter * unit(map_rng_);
    const double z = map.wall_height * unit(map_rng_);
    Eigen::Vector2d p;
    if (s < size.x()) {
      p = Eigen::Vector2d(lo.x() + s, lo.y());
    } else if ((s -= size.x()) < size.y()) {
      p = Eigen::Vector2d(lo.x() + size.x(), lo.y() + s);
    } else if ((s -= size.y()) < size.x()) {
      p = Eigen::Vector2d(lo.x() + size.x() - s, lo.y() + size.y());
    } else {
      s -= size.x();
      p = Eigen::Vector2d(lo.x(), lo.y() + size.y() - std::min(s, size.y()));
    }
    add_static_point(Eigen::Vector3d(p.x(), p.y(), z));
  }
}

void FeatureSimulator::make_target_points(const TargetConfig& target) {
  const Eigen::Vector3d half = 0.5 * target.size;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int axis = 0; axis < 3; ++axis) {
    for (const double sign : {1.0, -1.0}) {
      Eigen::Vector3d normal = Eigen::Vector3d::Zero();
      normal(axis) = sign;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      for (int k = 0; k < target.points_per_face; ++k) {
        Eigen::Vector3d p = sign * half(axis) * normal.cwiseAbs();
        p(a1) = (half(a1) - target.edge_margin) * (2.0 * unit(map_rng_) - 1.0);
        p(a2) = (half(a2) - target.edge_margin) * (2.0 * unit(map_rng_) - 1.0);
        Landmark lm;
        lm.id = static_cast<int64_t>(landmarks_.size());
        lm.is_target = true;
        lm.p = p;
        lm.normal_T = normal;
        landmarks_.push_back(lm);
        track_of_landmark_.push_back(-1);
        target_ids_.push_back(lm.id);
      }
    }
  }
}

int FeatureSimulator::cell_index(double x) const { return static_cast<int>(std::floor(x / cell_size_)); }

int64_t FeatureSimulator::cell_key(int ix, int iy, int iz) const {
  const int64_t mask = (int64_t{1} << kCellBits) - 1;
  return (((ix + kCellOffset) & mask) << (2 * kCellBits)) | (((iy + kCellOffset) & mask) << kCellBits) |
         ((iz + kCellOffset) & mask);
}

void FeatureSimulator::add_static_point(const Eigen::Vector3d& p_FinG) {
  Landmark lm;
  lm.id = static_cast<int64_t>(landmarks_.size());
  lm.p = p_FinG;
  landmarks_.push_back(lm);
  track_of_landmark_.push_back(-1);
  grid_[cell_key(cell_index(p_FinG.x()), cell_index(p_FinG.y()), cell_index(p_FinG.z()))].push_back(lm.id);
}

std::vector<int64_t> FeatureSimulator::static_candidates(const Eigen::Vector3d& center, double radius) const {
  std::vector<int64_t> out;
  const double r2 = radius * radius;
  const Eigen::Vector3i lo(cell_index(center.x() - radius), cell_index(center.y() - radius),
                           cell_index(center.z() - radius));
  const Eigen::Vector3i hi(cell_index(center.x() + radius), cell_index(center.y() + radius),
                           cell_index(center.z() + radius));
  for (int ix = lo.x(); ix <= hi.x(); ++ix) {
    for (int iy = lo.y(); iy <= hi.y(); ++iy) {
      for (int iz = lo.z(); iz <= hi.z(); ++iz) {
        const auto it = grid_.find(cell_key(ix, iy, iz));
        if (it == grid_.end()) continue;
        for (const int64_t id : it->second) {
          if ((landmarks_[static_cast<std::size_t>(id)].p - center).squaredNorm() <= r2) out.push_back(id);
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool FeatureSimulator::project(int cam, const CameraPose& pose, const Eigen::Vector3d& p_FinG,
                               Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d p_FinC = pose.R_GtoC * (p_FinG - pose.p_CinG);
  if (!(p_FinC.z() > config_.min_depth)) return false;
  if (config_.max_depth > 0.0 && p_FinC.z() > config_.max_depth) return false;
  if (p_FinC.squaredNorm() > config_.max_range * config_.max_range) return false;
  const Eigen::Vector2d n = p_FinC.head<2>() / p_FinC.z();
  if (!norm_bounds_[static_cast<std::size_t>(cam)].contains(n)) return false;
  const CameraModel& model = cameras_[static_cast<std::size_t>(cam)];
  *pixel = model.distort(n);
  return model.in_image(*pixel, config_.border);
}

bool FeatureSimulator::segment_hits_box(const Eigen::Vector3d& p_a, const Eigen::Vector3d& p_b,
                                        const Eigen::Vector3d& half_size) {
  // Slab test on the segment p_a + s (p_b - p_a), s in (0, 1): the end point
  // (the observed point) may lie on the box surface without being hidden.
  constexpr double kEps = 1e-9;
  const Eigen::Vector3d d = p_b - p_a;
  double s_in = 0.0, s_out = 1.0 - kEps;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d(k)) < 1e-15) {
      if (p_a(k) < -half_size(k) || p_a(k) > half_size(k)) return false;
      continue;
    }
    double s1 = (-half_size(k) - p_a(k)) / d(k);
    double s2 = (half_size(k) - p_a(k)) / d(k);
    if (s1 > s2) std::swap(s1, s2);
    s_in = std::max(s_in, s1);
    s_out = std::min(s_out, s2);
    if (s_in > s_out) return false;
  }
  return true;
}

bool FeatureSimulator::static_visible(int cam, const CameraPose& pose, const Eigen::Vector3d& p_FinG,
                                      const Eigen::Matrix4d* T_TtoG, Eigen::Vector2d* pixel) const {
  if (!project(cam, pose, p_FinG, pixel)) return false;
  if (T_TtoG == nullptr) return true;
  const Eigen::Matrix3d R_GtoT = T_TtoG->topLeftCorner<3, 3>().transpose();
  const Eigen::Vector3d p_TinG = T_TtoG->topRightCorner<3, 1>();
  return !segment_hits_box(R_GtoT * (pose.p_CinG - p_TinG), R_GtoT * (p_FinG - p_TinG), 0.5 * target_.size);
}

int64_t FeatureSimulator::landmark_of_feature(int64_t feature_id) const {
  const auto it = landmark_of_feature_.find(feature_id);
  return it == landmark_of_feature_.end() ? -1 : it->second;
}

CameraFrame FeatureSimulator::simulate(int64_t utime, const Eigen::Matrix4d& T_ItoG, const Eigen::Matrix4d* T_TtoG) {
  const Eigen::Matrix3d R_ItoG = T_ItoG.topLeftCorner<3, 3>();
  const Eigen::Vector3d p_IinG = T_ItoG.topRightCorner<3, 1>();
  const int n_cams = static_cast<int>(cameras_.size());
  const Eigen::Matrix4d* target = with_target_ ? T_TtoG : nullptr;

  std::vector<CameraPose> poses;
  for (int c = 0; c < n_cams; ++c) {
    const CameraCalibration& calib = cameras_[static_cast<std::size_t>(c)].calibration();
    poses.push_back({calib.R_ItoC * R_ItoG.transpose(), p_IinG + R_ItoG * p_CinI_[static_cast<std::size_t>(c)]});
  }

  // Geometric visibility per camera, in landmark-id order.
  std::vector<std::vector<Visible>> visible(static_cast<std::size_t>(n_cams));
  const std::vector<int64_t> candidates = static_candidates(p_IinG, config_.max_range + max_p_CinI_);
  for (int c = 0; c < n_cams; ++c) {
    for (const int64_t id : candidates) {
      Eigen::Vector2d px;
      if (static_visible(c, poses[static_cast<std::size_t>(c)], landmarks_[static_cast<std::size_t>(id)].p, target,
                         &px)) {
        visible[static_cast<std::size_t>(c)].push_back({id, px});
      }
    }
  }
  if (target != nullptr) {
    const Eigen::Matrix3d R_TtoG = target->topLeftCorner<3, 3>();
    const Eigen::Vector3d p_TinG = target->topRightCorner<3, 1>();
    for (int c = 0; c < n_cams; ++c) {
      const CameraPose& pose = poses[static_cast<std::size_t>(c)];
      for (const int64_t id : target_ids_) {
        const Landmark& lm = landmarks_[static_cast<std::size_t>(id)];
        const Eigen::Vector3d p_FinG = R_TtoG * lm.p + p_TinG;
        const Eigen::Vector3d to_cam = pose.p_CinG - p_FinG;
        if (!((R_TtoG * lm.normal_T).dot(to_cam) > target_.min_view_cos * to_cam.norm())) continue;
        Eigen::Vector2d px;
        if (project(c, pose, p_FinG, &px)) visible[static_cast<std::size_t>(c)].push_back({id, px});
      }
    }
  }

  // Keep-N: spawn static points in view of a camera that sees too few.
  if (config_.keep_per_camera > 0) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int c = 0; c < n_cams; ++c) {
      int n_static = 0;
      for (const Visible& v : visible[static_cast<std::size_t>(c)]) {
        if (!landmarks_[static_cast<std::size_t>(v.landmark)].is_target) ++n_static;
      }
      const CameraModel& model = cameras_[static_cast<std::size_t>(c)];
      const CameraPose& pose = poses[static_cast<std::size_t>(c)];
      for (int k = n_static; k < config_.keep_per_camera; ++k) {
        const double b = config_.border;
        const double u = b + unit(map_rng_) * (model.calibration().width - 1 - 2.0 * b);
        const double v = b + unit(map_rng_) * (model.calibration().height - 1 - 2.0 * b);
        const Eigen::Vector2d px(u, v);
        const double depth =
            config_.spawn_depth_min + (config_.spawn_depth_max - config_.spawn_depth_min) * unit(map_rng_);
        const Eigen::Vector3d p_FinC = depth * model.undistort(px).homogeneous();
        add_static_point(pose.R_GtoC.transpose() * p_FinC + pose.p_CinG);
        const Landmark& lm = landmarks_.back();
        for (int c2 = 0; c2 < n_cams; ++c2) {
          Eigen::Vector2d px2;
          if (static_visible(c2, poses[static_cast<std::size_t>(c2)], lm.p, target, &px2)) {
            visible[static_cast<std::size_t>(c2)].push_back({lm.id, px2});
          }
        }
      }
    }
  }

  // Keep-N cap: at most N static points per camera, those tracked in the
  // previous frame first, then by landmark id.
  if (config_.keep_per_camera > 0) {
    for (auto& vis : visible) {
      std::vector<Visible> tracked, fresh, targets;
      for (const Visible& v : vis) {
        if (landmarks_[static_cast<std::size_t>(v.landmark)].is_target) {
          targets.push_back(v);
        } else if (track_of_landmark_[static_cast<std::size_t>(v.landmark)] >= 0) {
          tracked.push_back(v);
        } else {
          fresh.push_back(v);
        }
      }
      const std::size_t n_max = static_cast<std::size_t>(config_.keep_per_camera);
      if (tracked.size() + fresh.size() <= n_max) continue;
      auto by_id = [](const Visible& a, const Visible& b) { return a.landmark < b.landmark; };
      std::sort(tracked.begin(), tracked.end(), by_id);
      std::sort(fresh.begin(), fresh.end(), by_id);
      vis.clear();
      for (const Visible& v : tracked) {
        if (vis.size() < n_max) vis.push_back(v);
      }
      for (const Visible& v : fresh) {
        if (vis.size() < n_max) vis.push_back(v);
      }
      vis.insert(vis.end(), targets.begin(), targets.end());
    }
  }

  // Track bookkeeping over the union of the cameras' visible points.
  std::vector<int64_t> seen;
  for (const auto& vis : visible) {
    for (const Visible& v : vis) seen.push_back(v.landmark);
  }
  std::sort(seen.begin(), seen.end());
  seen.erase(std::unique(seen.begin(), seen.end()), seen.end());
  for (const int64_t id : active_) {
    if (!std::binary_search(seen.begin(), seen.end(), id)) track_of_landmark_[static_cast<std::size_t>(id)] = -1;
  }
  active_.clear();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const int64_t id : seen) {
    int64_t& track = track_of_landmark_[static_cast<std::size_t>(id)];
    if (track >= 0 && config_.track_loss_probability > 0.0 && unit(track_rng_) < config_.track_loss_probability) {
      track = -1;  // lost: not reported now, a fresh id when seen again
      continue;
    }
    if (track < 0) {
      track = next_feature_id_++;
      landmark_of_feature_.emplace(track, id);
    }
    active_.push_back(id);
  }

  // Measurements of the tracked points.
  CameraFrame frame;
  frame.utime = utime;
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int c = 0; c < n_cams; ++c) {
    const CameraModel& model = cameras_[static_cast<std::size_t>(c)];
    std::vector<FeatureObservation> obs;
    for (const Visible& v : visible[static_cast<std::size_t>(c)]) {
      const int64_t track = track_of_landmark_[static_cast<std::size_t>(v.landmark)];
      if (track < 0) continue;
      FeatureObservation o;
      o.feature_id = track;
      o.camera_id = c;
      o.pixel = v.pixel;
      if (config_.pixel_noise > 0.0) {
        const double nx = normal(pixel_rng_);
        const double ny = normal(pixel_rng_);
        o.pixel += config_.pixel_noise * Eigen::Vector2d(nx, ny);
      }
      o.normalized = model.undistort(o.pixel);
      o.is_target = landmarks_[static_cast<std::size_t>(v.landmark)].is_target;
      obs.push_back(o);
    }
    std::sort(obs.begin(), obs.end(),
              [](const FeatureObservation& a, const FeatureObservation& b) { return a.feature_id < b.feature_id; });
    frame.observations.insert(frame.observations.end(), obs.begin(), obs.end());
  }
  return frame;
}

}  // namespace sim
}  // namespace vimot

#include "common/eval/tracker_accuracy.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

namespace vimot {
namespace eval {

namespace {

// A track's true point: in G (room) or in the target's frame.
struct TruePoint {
  Eigen::Vector3d p{Eigen::Vector3d::Zero()};
  bool on_target{false};
  int64_t first_frame{0};
};

// Distance from `px` to the box's outline: > 0 outside, <= 0 inside.
double box_distance(const Eigen::Vector4d& box, const Eigen::Vector2d& px) {
  const double x0 = box(0), y0 = box(1), x1 = box(0) + box(2), y1 = box(1) + box(3);
  const double dx = std::max({x0 - px.x(), 0.0, px.x() - x1});
  const double dy = std::max({y0 - px.y(), 0.0, px.y() - y1});
  if (dx > 0.0 || dy > 0.0) return std::hypot(dx, dy);
  return -std::min({px.x() - x0, x1 - px.x(), px.y() - y0, y1 - px.y()});
}

}  // namespace

ErrorSummary summarise(const std::vector<ObservationError>& errors) {
  ErrorSummary s;
  s.count = static_cast<int64_t>(errors.size());
  if (errors.empty()) return s;
  std::vector<double> e;
  e.reserve(errors.size());
  int64_t outliers = 0;
  for (const ObservationError& o : errors) {
    e.push_back(o.error_px);
    if (o.error_px > 3.0) ++outliers;
  }
  std::sort(e.begin(), e.end());
  auto rank = [&e](double q) {  // nearest rank
    const auto k = static_cast<std::size_t>(std::ceil(q * static_cast<double>(e.size())));
    return e[std::min(e.size() - 1, k == 0 ? 0 : k - 1)];
  };
  s.median_px = rank(0.5);
  s.p95_px = rank(0.95);
  s.outlier_fraction = static_cast<double>(outliers) / static_cast<double>(e.size());
  return s;
}

std::vector<ObservationError> tracker_errors(const sim::Simulator& sim, PixelFrontEnd* front, int64_t frames) {
  std::vector<ObservationError> out;
  std::unordered_map<int64_t, TruePoint> truth;
  const int64_t n = std::min(frames, sim.camera_frame_count());
  for (int64_t k = 0; k < n; ++k) {
    const int64_t utime = sim.camera_utime(k);
    const CameraFrame frame = front->frame(utime);
    const double t = sim.sim_time(utime);
    const sim::SplineState robot = sim.robot_state(t);
    const std::optional<sim::SplineState> target = sim.target_state(t);
    for (const FeatureObservation& f : frame.observations) {
      auto it = truth.find(f.feature_id);
      if (it == truth.end()) {
        const sim::Renderer::SurfaceHit hit = front->renderer().surface_at(f.camera_id, utime, f.pixel);
        TruePoint p;
        p.on_target = hit.on_target;
        p.first_frame = k;
        p.p = hit.on_target ? Eigen::Vector3d(target->R_BtoG.transpose() * (hit.p_inG - target->p_BinG))
                            : hit.p_inG;
        truth.emplace(f.feature_id, p);
        continue;
      }
      const TruePoint& p = it->second;
      if (p.on_target && !target) continue;
      const Eigen::Vector3d p_inG = p.on_target ? Eigen::Vector3d(target->R_BtoG * p.p + target->p_BinG) : p.p;
      const CameraCalibration& calib = sim.cameras()[static_cast<std::size_t>(f.camera_id)];
      const Eigen::Vector3d p_inC =
          calib.R_ItoC * (robot.R_BtoG.transpose() * (p_inG - robot.p_BinG)) + calib.p_IinC;
      ObservationError e;
      e.feature_id = f.feature_id;
      e.camera_id = f.camera_id;
      e.is_target = f.is_target;
      e.born_on_target = p.on_target;
      e.age = static_cast<int>(k - p.first_frame);
      if (p_inC.z() <= 1e-6) {
        e.error_px = std::numeric_limits<double>::infinity();  // tracked onto a point behind the camera
      } else {
        const Eigen::Vector2d projected = sim.camera_models()[static_cast<std::size_t>(f.camera_id)].distort(
            p_inC.head<2>() / p_inC.z());
        e.error_px = (f.pixel - projected).norm();
      }
      const auto& views = front->last_views();
      const auto cam = static_cast<std::size_t>(f.camera_id);
      e.box_distance_px = cam < views.size() && views[cam].visible ? box_distance(views[cam].box, f.pixel)
                                                                    : std::numeric_limits<double>::infinity();
      out.push_back(e);
    }
  }
  return out;
}

}  // namespace eval
}  // namespace vimot

#include "common/target/target_checkpoint.h"

#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

namespace vimot {
namespace target {

namespace {

enum : int32_t {
  kTarget = estimator::kFirstExtensionKind,
  kTargetClone = estimator::kFirstExtensionKind + 1,
  kTargetPoint = estimator::kFirstExtensionKind + 2,
};

}  // namespace

bool TargetCheckpoint::describe(const estimator::Type* var, int32_t* kind, int64_t* key) const {
  if (filter_.target() && var == filter_.target().get()) {
    *kind = kTarget;
    *key = 0;
    return true;
  }
  for (const auto& [utime, pose] : filter_.clones()) {
    if (var == pose.get()) {
      *kind = kTargetClone;
      *key = utime;
      return true;
    }
  }
  for (const auto& [id, point] : filter_.points()) {
    if (var == point.var.get()) {
      *kind = kTargetPoint;
      *key = id;
      return true;
    }
  }
  return false;
}

estimator::TypePtr TargetCheckpoint::make(int32_t kind, int64_t /*key*/) const {
  switch (kind) {
    case kTarget:
      return std::make_shared<TargetState>();
    case kTargetClone:
      return std::make_shared<estimator::PoseJPL>();
    case kTargetPoint:
      return std::make_shared<estimator::Vec>(3);
    default:
      return nullptr;
  }
}

std::string TargetCheckpoint::save() const {
  const TargetFilterOptions& o = filter_.options();
  estimator::CheckpointWriter w;
  w.put(static_cast<int32_t>(o.representation));
  w.put(static_cast<int32_t>(o.mode));
  w.put(static_cast<uint8_t>(o.planar));
  w.put(filter_.frame_count());
  w.put(filter_.starts());
  w.put(static_cast<uint8_t>(filter_.model_verified()));
  w.put(filter_.sigma_at_start());
  w.put(static_cast<int64_t>(filter_.points().size()));
  for (const auto& [id, point] : filter_.points()) {
    w.put(id);
    w.put(point.last_updated_frame);
  }
  w.put(filter_.tracks());
  w.put(static_cast<uint8_t>(filter_.adaptive() != nullptr));
  if (filter_.adaptive() != nullptr) filter_.adaptive()->save(&w);
  return std::move(w.bytes());
}

bool TargetCheckpoint::load(
    const std::vector<std::pair<const estimator::CheckpointVariable*, estimator::TypePtr>>& variables,
    const std::string& memory, std::string* why) {
  const TargetFilterOptions& o = filter_.options();
  estimator::CheckpointReader r(memory.data(), memory.size());
  const auto representation = static_cast<TargetRepresentation>(r.take<int32_t>());
  const auto mode = static_cast<TargetUpdateMode>(r.take<int32_t>());
  const bool planar = r.take<uint8_t>() != 0;
  if (r.ok() && (representation != o.representation || mode != o.mode || planar != o.planar)) {
    std::ostringstream msg;
    msg << "written by a target filter with another configuration (representation "
        << static_cast<int>(representation) << ", mode " << static_cast<int>(mode) << ", planar " << planar
        << "; this one: " << to_string(o.representation) << ", " << to_string(o.mode) << ", " << o.planar << ")";
    *why = msg.str();
    return false;
  }
  const int64_t frame = r.take<int64_t>();
  const int32_t starts = r.take<int32_t>();
  const bool model_verified = r.take<uint8_t>() != 0;
  const double sigma_at_start = r.take<double>();
  const int64_t n_points = r.take<int64_t>();
  std::map<int64_t, int64_t> last_updated;
  for (int64_t i = 0; r.ok() && i < n_points; ++i) {
    const int64_t id = r.take<int64_t>();
    last_updated[id] = r.take<int64_t>();
  }
  estimator::FeatureDatabase tracks = r.take_tracks();
  std::optional<AdaptiveNoise> adaptive;
  bool adaptive_ok = true;
  if (r.take<uint8_t>() != 0 && filter_.adaptive() != nullptr) {  // the same mode: both or neither
    adaptive = *filter_.adaptive();
    adaptive_ok = adaptive->load(&r);
  }
  if (!adaptive_ok || !r.ok() || !r.at_end()) {
    *why = "its target filter part is cut short or corrupt";
    return false;
  }
  std::shared_ptr<TargetState> target;
  std::map<int64_t, std::shared_ptr<estimator::PoseJPL>> clones;
  std::map<int64_t, TargetPoint> points;
  for (const auto& [v, var] : variables) {
    if (v->kind == kTarget) target = std::dynamic_pointer_cast<TargetState>(var);
    if (v->kind == kTargetClone) clones[v->key] = std::dynamic_pointer_cast<estimator::PoseJPL>(var);
    if (v->kind == kTargetPoint) {
      const auto it = last_updated.find(v->key);
      if (it == last_updated.end()) {
        *why = "target point " + std::to_string(v->key) + " has no bookkeeping";
        return false;
      }
      points[v->key] = TargetPoint{std::dynamic_pointer_cast<estimator::Vec>(var), it->second};
    }
  }
  if (points.size() != last_updated.size() || (!target && (!clones.empty() || !points.empty())) || starts < 0 ||
      (target && starts == 0) || !std::isfinite(sigma_at_start)) {
    *why = "its target variables do not match its bookkeeping";
    return false;
  }
  filter_.restore(std::move(target), std::move(clones), std::move(points), std::move(tracks), frame,
                  std::move(adaptive), starts, model_verified, sigma_at_start);
  return true;
}

}  // namespace target
}  // namespace vimot

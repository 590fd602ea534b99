#include "common/estimator/feature_database.h"

#include <algorithm>
#include <limits>

namespace vimot {
namespace estimator {

int Feature::num_obs() const {
  int n = 0;
  for (const auto& kv : obs) n += static_cast<int>(kv.second.size());
  return n;
}

int64_t Feature::first_utime() const {
  int64_t t = std::numeric_limits<int64_t>::max();
  for (const auto& kv : obs) {
    if (!kv.second.empty()) t = std::min(t, kv.second.front().utime);
  }
  return t;
}

int64_t Feature::last_utime() const {
  int64_t t = std::numeric_limits<int64_t>::min();
  for (const auto& kv : obs) {
    if (!kv.second.empty()) t = std::max(t, kv.second.back().utime);
  }
  return t;
}

std::set<int64_t> Feature::times() const {
  std::set<int64_t> t;
  for (const auto& kv : obs) {
    for (const auto& o : kv.second) t.insert(o.utime);
  }
  return t;
}

bool Feature::observed_at(int64_t utime) const {
  for (const auto& kv : obs) {
    if (!kv.second.empty() && kv.second.back().utime == utime) return true;
    for (const auto& o : kv.second) {
      if (o.utime == utime) return true;
    }
  }
  return false;
}

int Feature::keep_times(const std::set<int64_t>& keep) {
  int n = 0;
  for (auto it = obs.begin(); it != obs.end();) {
    auto& v = it->second;
    v.erase(std::remove_if(v.begin(), v.end(), [&](const FeatureObs& o) { return keep.count(o.utime) == 0; }),
            v.end());
    n += static_cast<int>(v.size());
    it = v.empty() ? obs.erase(it) : std::next(it);
  }
  return n;
}

void FeatureDatabase::add(int64_t utime, int64_t feature_id, int camera_id, const Eigen::Vector2d& uv) {
  auto& f = features_[feature_id];
  if (!f) {
    f = std::make_shared<Feature>();
    f->feature_id = feature_id;
  }
  auto& v = f->obs[camera_id];
  if (!v.empty() && v.back().utime >= utime) return;
  v.push_back(FeatureObs{utime, uv});
}

std::vector<std::shared_ptr<Feature>> FeatureDatabase::lost_before(int64_t utime) const {
  std::vector<std::shared_ptr<Feature>> out;
  for (const auto& kv : features_) {
    if (kv.second->last_utime() < utime) out.push_back(kv.second);
  }
  return out;
}

std::vector<std::shared_ptr<Feature>> FeatureDatabase::observed_at(int64_t utime) const {
  std::vector<std::shared_ptr<Feature>> out;
  for (const auto& kv : features_) {
    if (kv.second->observed_at(utime)) out.push_back(kv.second);
  }
  return out;
}

std::shared_ptr<Feature> FeatureDatabase::get(int64_t feature_id) const {
  const auto it = features_.find(feature_id);
  return it == features_.end() ? nullptr : it->second;
}

void FeatureDatabase::remove(int64_t feature_id) { features_.erase(feature_id); }

void FeatureDatabase::clean_older_than(int64_t utime) {
  for (auto it = features_.begin(); it != features_.end();) {
    auto& f = *it->second;
    for (auto c = f.obs.begin(); c != f.obs.end();) {
      auto& v = c->second;
      v.erase(std::remove_if(v.begin(), v.end(), [&](const FeatureObs& o) { return o.utime < utime; }), v.end());
      c = v.empty() ? f.obs.erase(c) : std::next(c);
    }
    it = f.obs.empty() ? features_.erase(it) : std::next(it);
  }
}

}  // namespace estimator
}  // namespace vimot

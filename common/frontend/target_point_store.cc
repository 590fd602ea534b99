#include "common/frontend/target_point_store.h"

#include <algorithm>
#include <limits>
#include <tuple>

namespace vimot::frontend {

void TargetPointStore::update(int64_t id, const Descriptor& descriptor, int64_t frame_index) {
  points_[id] = Entry{descriptor, frame_index};
  while (points_.size() > static_cast<std::size_t>(options_.max_stored_points)) {
    auto oldest = points_.begin();
    for (auto it = points_.begin(); it != points_.end(); ++it) {
      if (std::tie(it->second.last_frame, it->first) < std::tie(oldest->second.last_frame, oldest->first)) {
        oldest = it;
      }
    }
    points_.erase(oldest);
  }
}

std::vector<int64_t> TargetPointStore::match(const std::vector<Descriptor>& queries,
                                             const std::set<int64_t>& exclude) const {
  struct Candidate {
    int distance;
    std::size_t query;
    int64_t id;
  };
  std::vector<Candidate> candidates;
  for (std::size_t q = 0; q < queries.size(); ++q) {
    int best = std::numeric_limits<int>::max(), second = best;
    int64_t best_id = -1;
    for (const auto& [id, entry] : points_) {
      if (exclude.count(id) != 0) continue;
      const int d = hamming_distance(queries[q], entry.descriptor);
      if (d < best || (d == best && id < best_id)) {
        second = best;
        best = d;
        best_id = id;
      } else if (d < second) {
        second = d;
      }
    }
    if (best_id < 0 || best > options_.loop_closure_max_hamming) continue;
    if (second != std::numeric_limits<int>::max() && !(best < options_.match_ratio * second)) continue;
    candidates.push_back({best, q, best_id});
  }
  // Nearest first, so a stored point claimed twice goes to its best match.
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.distance, a.query) < std::tie(b.distance, b.query);
  });
  std::vector<int64_t> out(queries.size(), -1);
  std::set<int64_t> taken;
  for (const Candidate& c : candidates) {
    if (taken.insert(c.id).second) out[c.query] = c.id;
  }
  return out;
}

}  // namespace vimot::frontend

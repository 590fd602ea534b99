#pragma once
// The descriptors of the target's points seen so far, for target loop
// closure: a new target track whose descriptor matches a stored point that
// is not in view gets that point's old id back, so the estimator sees a
// re-observed target point instead of a new one (Section VI-B of the
// Schmidt-EKF paper: these re-identifications limit the target's drift).
// No LCM here.

#include <cstdint>
#include <set>
#include <unordered_map>
#include <vector>

#include "common/frontend/orb_features.h"
#include "common/frontend/tracker_options.h"

namespace vimot::frontend {

class TargetPointStore {
 public:
  explicit TargetPointStore(const TargetTrackOptions& options) : options_(options) {}

  /// Stores (or refreshes) the descriptor of target point `id`, seen in
  /// frame `frame_index`. Beyond options.max_stored_points the point seen
  /// longest ago is forgotten.
  void update(int64_t id, const Descriptor& descriptor, int64_t frame_index);

  /// For each query descriptor, the id of a stored point not in `exclude`
  /// that it matches (distance <= loop_closure_max_hamming and clearly
  /// nearer than the second-nearest stored point), or -1. Each stored id is
  /// given to at most one query, the nearest.
  std::vector<int64_t> match(const std::vector<Descriptor>& queries, const std::set<int64_t>& exclude) const;

  std::size_t size() const { return points_.size(); }

 private:
  struct Entry {
    Descriptor descriptor{};
    int64_t last_frame{0};
  };
  TargetTrackOptions options_;
  std::unordered_map<int64_t, Entry> points_;
};

}  // namespace vimot::frontend

#pragma once
// Small pieces shared by the visual updaters.

#include <Eigen/Core>
#include <map>
#include <vector>

#include "common/estimator/types.h"

namespace vimot {
namespace estimator {

/// Column layout of a measurement Jacobian over a set of variables: each
/// variable gets its block the first time it is asked for, in that order.
class ColumnLayout {
 public:
  /// First column of `var`'s block (allocated on first use).
  int col(const TypePtr& var) {
    const auto it = cols_.find(var.get());
    if (it != cols_.end()) return it->second;
    const int c = total_;
    cols_[var.get()] = c;
    order_.push_back(var);
    total_ += var->size();
    return c;
  }
  bool has(const TypePtr& var) const { return cols_.count(var.get()) != 0; }
  int total() const { return total_; }
  const std::vector<TypePtr>& order() const { return order_; }

 private:
  std::map<const Type*, int> cols_;
  std::vector<TypePtr> order_;
  int total_{0};
};

/// Counters of one camera frame (and, summed, of a run).
struct UpdateStats {
  int msckf_candidates{0};        // features offered to the MSCKF update
  int msckf_used{0};              // passed triangulation and chi²
  int msckf_rejected_short{0};    // seen at fewer than min_clone_times clone times
  int msckf_rejected_triangulation{0};
  int msckf_rejected_chi2{0};
  int msckf_dropped_over_max{0};  // above max_msckf_in_update
  int msckf_rows{0};              // rows after projection, before compression
  int slam_updated{0};            // SLAM features updated
  int slam_rejected_chi2{0};
  int slam_initialized{0};
  int slam_init_rejected{0};      // triangulation or chi² failed at initialisation
  int slam_marginalized{0};
  int slam_in_state{0};

  void accumulate(const UpdateStats& o) {
    msckf_candidates += o.msckf_candidates;
    msckf_used += o.msckf_used;
    msckf_rejected_short += o.msckf_rejected_short;
    msckf_rejected_triangulation += o.msckf_rejected_triangulation;
    msckf_rejected_chi2 += o.msckf_rejected_chi2;
    msckf_dropped_over_max += o.msckf_dropped_over_max;
    msckf_rows += o.msckf_rows;
    slam_updated += o.slam_updated;
    slam_rejected_chi2 += o.slam_rejected_chi2;
    slam_initialized += o.slam_initialized;
    slam_init_rejected += o.slam_init_rejected;
    slam_marginalized += o.slam_marginalized;
    slam_in_state = o.slam_in_state;
  }
};

}  // namespace estimator
}  // namespace vimot

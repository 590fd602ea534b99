#pragma once
// The target filter's part of an estimator checkpoint
// (common/estimator/checkpoint.h): its variables in the state — the target,
// its pose clones (keyed by clone utime) and its points (keyed by feature
// id) — and its bookkeeping: the configuration it must match
// (representation, mode, planar), the frame count the points' ages are
// counted in, each point's last update, the target feature tracks and the
// σ_t estimate (adaptive mode). A filter restored from it continues bit for
// bit as the one that wrote it. A partial feature initialisation (before the
// target is acquired) is not kept: acquisition starts again. No LCM here.

#include <string>
#include <utility>
#include <vector>

#include "common/estimator/checkpoint.h"
#include "common/target/target_filter.h"

namespace vimot {
namespace target {

class TargetCheckpoint : public estimator::CheckpointExtension {
 public:
  /// `filter` must outlive this.
  explicit TargetCheckpoint(TargetFilter& filter) : filter_(filter) {}

  bool describe(const estimator::Type* var, int32_t* kind, int64_t* key) const override;
  estimator::TypePtr make(int32_t kind, int64_t key) const override;
  std::string save() const override;
  bool load(const std::vector<std::pair<const estimator::CheckpointVariable*, estimator::TypePtr>>& variables,
            const std::string& memory, std::string* why) override;

 private:
  TargetFilter& filter_;
};

}  // namespace target
}  // namespace vimot

#include "common/process/lcm_type_registry.h"

#include "vimot/features_t.hpp"
#include "vimot/ground_truth_t.hpp"
#include "vimot/heartbeat_t.hpp"
#include "vimot/image_t.hpp"
#include "vimot/imu_t.hpp"
#include "vimot/mask_t.hpp"
#include "vimot/metric_object_pose_t.hpp"
#include "vimot/nav_state_t.hpp"
#include "vimot/object_pose_t.hpp"
#include "vimot/scale_estimate_t.hpp"
#include "vimot/target_box_t.hpp"
#include "vimot/target_prediction_t.hpp"
#include "vimot/target_state_t.hpp"

namespace vimot {

namespace {
template <typename Msg>
LcmTypeInfo info() {
  return LcmTypeInfo{std::string("vimot.") + Msg::getTypeName(), Msg::getHash(),
                     +[](const void* data, int size) {
                       Msg msg;
                       return msg.decode(data, 0, size) == size;
                     }};
}

int64_t read_fingerprint(const void* data) {
  // LCM writes the fingerprint big-endian.
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
  return static_cast<int64_t>(v);
}
}  // namespace

const std::vector<LcmTypeInfo>& vimot_lcm_types() {
  // Top-level messages only: nested types (feature_obs_t, image_metadata_t)
  // are never published on their own.
  static const std::vector<LcmTypeInfo> types{
      info<features_t>(),      info<ground_truth_t>(),   info<heartbeat_t>(),
      info<image_t>(),         info<imu_t>(),            info<mask_t>(),
      info<metric_object_pose_t>(), info<nav_state_t>(), info<object_pose_t>(),
      info<scale_estimate_t>(), info<target_box_t>(),    info<target_prediction_t>(),
      info<target_state_t>()};
  return types;
}

const LcmTypeInfo* find_lcm_type(const void* data, int size) {
  if (size < 8) return nullptr;
  const int64_t fp = read_fingerprint(data);
  for (const LcmTypeInfo& t : vimot_lcm_types()) {
    if (t.fingerprint == fp) return &t;
  }
  return nullptr;
}

}  // namespace vimot

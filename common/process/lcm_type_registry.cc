#include "common/process/lcm_type_registry.h"

#include <stdexcept>

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
LcmTypeInfo info(const LcmStruct& layout) {
  const std::string name = std::string("vimot.") + Msg::getTypeName();
  if (lcm_fingerprint(layout) != Msg::getHash()) {
    throw std::logic_error("the layout of " + name +
                           " in lcm_type_registry.cc does not match its .lcm file (fingerprints differ)");
  }
  return LcmTypeInfo{name, Msg::getHash(), &layout, +[](const void* data, int size) {
                       Msg msg;
                       return decode_untrusted(data, size, &msg);
                     }};
}

// LCM writes integers (the fingerprint, utime) big-endian.
int64_t read_be_int64(const void* data) {
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | b[i];
  return static_cast<int64_t>(v);
}
}  // namespace

const std::vector<LcmTypeInfo>& vimot_lcm_types() {
  // Wire layouts, member by member as in lcmtypes/vimot_<type>.lcm; info()
  // checks each against the generated fingerprint.
  static const LcmStruct feature_obs{"feature_obs_t", {
      {"feature_id", LcmKind::kInt64},
      {"camera_id", LcmKind::kInt8},
      {"u", LcmKind::kDouble},
      {"v", LcmKind::kDouble},
      {"x_norm", LcmKind::kDouble},
      {"y_norm", LcmKind::kDouble},
      {"is_target", LcmKind::kBoolean}}};
  static const LcmStruct image_metadata{"image_metadata_t", {
      {"key", LcmKind::kString},
      {"n", LcmKind::kInt32},
      {"value", LcmKind::kByte, "n"}}};
  static const LcmStruct features{"features_t", {
      {"utime", LcmKind::kInt64},
      {"num_obs", LcmKind::kInt32},
      {"obs", feature_obs, "num_obs"}}};
  static const LcmStruct ground_truth{"ground_truth_t", {
      {"utime", LcmKind::kInt64},
      {"q_GtoI", LcmKind::kDouble, "4"},
      {"p_IinG", LcmKind::kDouble, "3"},
      {"v_IinG", LcmKind::kDouble, "3"},
      {"w_IinI", LcmKind::kDouble, "3"},
      {"a_IinG", LcmKind::kDouble, "3"},
      {"bias_gyro", LcmKind::kDouble, "3"},
      {"bias_accel", LcmKind::kDouble, "3"},
      {"target_valid", LcmKind::kBoolean},
      {"q_GtoT", LcmKind::kDouble, "4"},
      {"p_TinG", LcmKind::kDouble, "3"},
      {"v_TinT", LcmKind::kDouble, "3"},
      {"w_TinT", LcmKind::kDouble, "3"}}};
  static const LcmStruct heartbeat{"heartbeat_t", {
      {"utime", LcmKind::kInt64},
      {"name", LcmKind::kString},
      {"pid", LcmKind::kInt32},
      {"messages_in", LcmKind::kInt64},
      {"messages_out", LcmKind::kInt64},
      {"decode_errors", LcmKind::kInt64},
      {"dropped", LcmKind::kInt64},
      {"errors", LcmKind::kInt64},
      {"status", LcmKind::kString},
      {"last_error", LcmKind::kString},
      {"num_counters", LcmKind::kInt32},
      {"counter_names", LcmKind::kString, "num_counters"},
      {"counter_values", LcmKind::kInt64, "num_counters"}}};
  static const LcmStruct image{"image_t", {
      {"utime", LcmKind::kInt64},
      {"width", LcmKind::kInt32},
      {"height", LcmKind::kInt32},
      {"row_stride", LcmKind::kInt32},
      {"pixelformat", LcmKind::kInt32},
      {"size", LcmKind::kInt32},
      {"data", LcmKind::kByte, "size"},
      {"nmetadata", LcmKind::kInt32},
      {"metadata", image_metadata, "nmetadata"}}};
  static const LcmStruct imu{"imu_t", {
      {"utime", LcmKind::kInt64},
      {"angular_velocity", LcmKind::kDouble, "3"},
      {"linear_acceleration", LcmKind::kDouble, "3"}}};
  static const LcmStruct mask{"mask_t", {
      {"utime", LcmKind::kInt64},
      {"camera_id", LcmKind::kInt8},
      {"width", LcmKind::kInt32},
      {"height", LcmKind::kInt32},
      {"size", LcmKind::kInt32},
      {"data", LcmKind::kByte, "size"}}};
  static const LcmStruct metric_object_pose{"metric_object_pose_t", {
      {"utime", LcmKind::kInt64},
      {"scale", LcmKind::kDouble},
      {"q_GtoO", LcmKind::kDouble, "4"},
      {"p_OinG", LcmKind::kDouble, "3"}}};
  static const LcmStruct nav_state{"nav_state_t", {
      {"utime", LcmKind::kInt64},
      {"updated", LcmKind::kBoolean},
      {"q_GtoI", LcmKind::kDouble, "4"},
      {"p_IinG", LcmKind::kDouble, "3"},
      {"v_IinG", LcmKind::kDouble, "3"},
      {"bias_gyro", LcmKind::kDouble, "3"},
      {"bias_accel", LcmKind::kDouble, "3"},
      {"covariance", LcmKind::kDouble, "225"},
      {"num_clones", LcmKind::kInt32},
      {"num_slam_features", LcmKind::kInt32},
      {"num_msckf_features", LcmKind::kInt32}}};
  static const LcmStruct object_pose{"object_pose_t", {
      {"utime", LcmKind::kInt64},
      {"valid", LcmKind::kBoolean},
      {"q_OtoC", LcmKind::kDouble, "4"},
      {"p_OinC", LcmKind::kDouble, "3"},
      {"num_features", LcmKind::kInt32},
      {"reprojection_rms", LcmKind::kDouble},
      {"track_id", LcmKind::kInt64}}};
  static const LcmStruct scale_estimate{"scale_estimate_t", {
      {"utime", LcmKind::kInt64},
      {"scale", LcmKind::kDouble},
      {"accepted", LcmKind::kBoolean},
      {"f_value", LcmKind::kDouble},
      {"condition", LcmKind::kDouble, "3"},
      {"condition_ok", LcmKind::kBoolean, "3"},
      {"failed_condition", LcmKind::kInt8},
      {"num_observations", LcmKind::kInt32}}};
  static const LcmStruct target_box{"target_box_t", {
      {"utime", LcmKind::kInt64},
      {"camera_id", LcmKind::kInt8},
      {"raw_valid", LcmKind::kBoolean},
      {"raw_box", LcmKind::kDouble, "4"},
      {"filtered_valid", LcmKind::kBoolean},
      {"filtered_box", LcmKind::kDouble, "4"},
      {"filtered_velocity", LcmKind::kDouble, "2"},
      {"filtered_covariance", LcmKind::kDouble, "16"},
      {"frames_since_raw", LcmKind::kInt32}}};
  static const LcmStruct target_prediction{"target_prediction_t", {
      {"utime", LcmKind::kInt64},
      {"prediction_utime", LcmKind::kInt64},
      {"q_GtoT", LcmKind::kDouble, "4"},
      {"p_TinG", LcmKind::kDouble, "3"},
      {"q_ItoT", LcmKind::kDouble, "4"},
      {"p_TinI", LcmKind::kDouble, "3"},
      {"covariance", LcmKind::kDouble, "36"}}};
  static const LcmStruct target_state{"target_state_t", {
      {"utime", LcmKind::kInt64},
      {"representation", LcmKind::kInt8},
      {"q_ItoT", LcmKind::kDouble, "4"},
      {"p_TinI", LcmKind::kDouble, "3"},
      {"q_GtoT", LcmKind::kDouble, "4"},
      {"p_TinG", LcmKind::kDouble, "3"},
      {"v_TinT", LcmKind::kDouble, "3"},
      {"w_TinT", LcmKind::kDouble, "3"},
      {"covariance", LcmKind::kDouble, "144"},
      {"num_target_points", LcmKind::kInt32},
      {"start_count", LcmKind::kInt32}}};

  // Top-level messages only: nested types (feature_obs_t, image_metadata_t)
  // are never published on their own.
  static const std::vector<LcmTypeInfo> types{
      info<features_t>(features),
      info<ground_truth_t>(ground_truth),
      info<heartbeat_t>(heartbeat),
      info<image_t>(image),
      info<imu_t>(imu),
      info<mask_t>(mask),
      info<metric_object_pose_t>(metric_object_pose),
      info<nav_state_t>(nav_state),
      info<object_pose_t>(object_pose),
      info<scale_estimate_t>(scale_estimate),
      info<target_box_t>(target_box),
      info<target_prediction_t>(target_prediction),
      info<target_state_t>(target_state)};
  return types;
}

int64_t vimot_message_utime(const void* data, int size) {
  if (size < 16) return -1;
  return read_be_int64(static_cast<const uint8_t*>(data) + 8);
}

const LcmTypeInfo* find_lcm_type(const void* data, int size) {
  if (size < 8) return nullptr;
  const int64_t fp = read_be_int64(data);
  for (const LcmTypeInfo& t : vimot_lcm_types()) {
    if (t.fingerprint == fp) return &t;
  }
  return nullptr;
}

const LcmStruct& vimot_lcm_layout(int64_t fingerprint, const std::string& type_name) {
  for (const LcmTypeInfo& t : vimot_lcm_types()) {
    if (t.fingerprint == fingerprint) return *t.layout;
  }
  throw std::logic_error(type_name + " is not a registered vimot LCM type (common/process/lcm_type_registry.cc)");
}

}  // namespace vimot

#pragma once
// One sample of every vimot LCM message, each field set to a distinctive
// non-zero value, so a field that is lost, swapped with another or left
// uninitialised shows up in a comparison. Shared by the C++ tests and the
// log writer of the Java (lcm-spy) decode test. No Catch here on purpose.

#include <cstddef>
#include <cstdint>

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

namespace vimot_test {

/// Hands out values that differ from each other and from zero.
class Distinct {
 public:
  double real() {
    ++n_;
    return 0.5 + 1.0625 * static_cast<double>(n_) * (n_ % 2 ? 1.0 : -1.0);
  }
  int32_t i32() { return 1000 + 7 * (++n_); }
  int64_t i64() { return (int64_t{1} << 40) + (++n_); }  // needs more than 32 bits
  template <std::size_t N>
  void fill(double (&a)[N]) {
    for (double& x : a) x = real();
  }

 private:
  int n_{0};
};

inline vimot::imu_t sample_imu() {
  Distinct d;
  vimot::imu_t m{};
  m.utime = d.i64();
  d.fill(m.angular_velocity);
  d.fill(m.linear_acceleration);
  return m;
}

/// 7x3 RGB with rows padded to 24 bytes, and two metadata entries (one with
/// an empty value) so both length fields of the nested type are exercised.
inline vimot::image_t sample_image() {
  Distinct d;
  vimot::image_t m{};
  m.utime = d.i64();
  m.width = 7;
  m.height = 3;
  m.row_stride = 24;
  m.pixelformat = vimot::image_t::PIXEL_FORMAT_RGB;
  m.size = m.row_stride * m.height;
  for (int i = 0; i < m.size; ++i) m.data.push_back(static_cast<uint8_t>(37 * i + 11));
  vimot::image_metadata_t exposure{};
  exposure.key = "exposure_us";
  exposure.value = {0x00, 0x01, 0xfe, 0xff, 0x80};
  exposure.n = static_cast<int32_t>(exposure.value.size());
  vimot::image_metadata_t flag{};
  flag.key = "flag_without_value";
  flag.n = 0;
  m.metadata = {exposure, flag};
  m.nmetadata = static_cast<int32_t>(m.metadata.size());
  return m;
}

/// Observations alternate cameras; every third is on the target.
inline vimot::features_t sample_features(int num_obs = 5) {
  Distinct d;
  vimot::features_t m{};
  m.utime = d.i64();
  for (int i = 0; i < num_obs; ++i) {
    vimot::feature_obs_t o{};
    o.feature_id = d.i64();
    o.camera_id = static_cast<int8_t>(i % 2);
    o.u = d.real();
    o.v = d.real();
    o.x_norm = d.real();
    o.y_norm = d.real();
    o.is_target = (i % 3 == 1);
    m.obs.push_back(o);
  }
  m.num_obs = num_obs;
  return m;
}

inline vimot::mask_t sample_mask() {
  Distinct d;
  vimot::mask_t m{};
  m.utime = d.i64();
  m.camera_id = 1;
  m.width = 5;
  m.height = 4;
  m.size = m.width * m.height;
  for (int i = 0; i < m.size; ++i) m.data.push_back(static_cast<uint8_t>(i % 3 ? 0 : 255 - i));
  return m;
}

inline vimot::target_box_t sample_target_box() {
  Distinct d;
  vimot::target_box_t m{};
  m.utime = d.i64();
  m.camera_id = 1;
  m.raw_valid = true;
  d.fill(m.raw_box);
  m.filtered_valid = true;
  d.fill(m.filtered_box);
  d.fill(m.filtered_velocity);
  d.fill(m.filtered_covariance);
  m.frames_since_raw = d.i32();
  return m;
}

inline vimot::nav_state_t sample_nav_state() {
  Distinct d;
  vimot::nav_state_t m{};
  m.utime = d.i64();
  m.updated = true;
  d.fill(m.q_GtoI);
  d.fill(m.p_IinG);
  d.fill(m.v_IinG);
  d.fill(m.bias_gyro);
  d.fill(m.bias_accel);
  d.fill(m.covariance);
  m.num_clones = d.i32();
  m.num_slam_features = d.i32();
  m.num_msckf_features = d.i32();
  return m;
}

inline vimot::target_state_t sample_target_state() {
  Distinct d;
  vimot::target_state_t m{};
  m.utime = d.i64();
  m.representation = vimot::target_state_t::LOCAL;
  d.fill(m.q_ItoT);
  d.fill(m.p_TinI);
  d.fill(m.q_GtoT);
  d.fill(m.p_TinG);
  d.fill(m.v_TinT);
  d.fill(m.w_TinT);
  d.fill(m.covariance);
  m.num_target_points = d.i32();
  m.start_count = d.i32();
  return m;
}

inline vimot::target_prediction_t sample_target_prediction() {
  Distinct d;
  vimot::target_prediction_t m{};
  m.utime = d.i64();
  m.prediction_utime = d.i64();
  d.fill(m.q_GtoT);
  d.fill(m.p_TinG);
  d.fill(m.q_ItoT);
  d.fill(m.p_TinI);
  d.fill(m.covariance);
  return m;
}

inline vimot::object_pose_t sample_object_pose() {
  Distinct d;
  vimot::object_pose_t m{};
  m.utime = d.i64();
  m.valid = true;
  d.fill(m.q_OtoC);
  d.fill(m.p_OinC);
  m.num_features = d.i32();
  m.reprojection_rms = d.real();
  m.track_id = d.i64();
  return m;
}

inline vimot::scale_estimate_t sample_scale_estimate() {
  Distinct d;
  vimot::scale_estimate_t m{};
  m.utime = d.i64();
  m.scale = d.real();
  m.accepted = true;
  m.f_value = d.real();
  d.fill(m.condition);
  m.condition_ok[0] = true;  // mixed, so element order is checked too
  m.condition_ok[1] = false;
  m.condition_ok[2] = true;
  m.failed_condition = 2;
  m.num_observations = d.i32();
  return m;
}

inline vimot::metric_object_pose_t sample_metric_object_pose() {
  Distinct d;
  vimot::metric_object_pose_t m{};
  m.utime = d.i64();
  m.scale = d.real();
  d.fill(m.q_GtoO);
  d.fill(m.p_OinG);
  return m;
}

inline vimot::ground_truth_t sample_ground_truth() {
  Distinct d;
  vimot::ground_truth_t m{};
  m.utime = d.i64();
  d.fill(m.q_GtoI);
  d.fill(m.p_IinG);
  d.fill(m.v_IinG);
  d.fill(m.w_IinI);
  d.fill(m.a_IinG);
  d.fill(m.bias_gyro);
  d.fill(m.bias_accel);
  m.target_valid = true;
  d.fill(m.q_GtoT);
  d.fill(m.p_TinG);
  d.fill(m.v_TinT);
  d.fill(m.w_TinT);
  return m;
}

inline vimot::heartbeat_t sample_heartbeat() {
  Distinct d;
  vimot::heartbeat_t m{};
  m.utime = d.i64();
  m.name = "target_filter";
  m.pid = d.i32();
  m.messages_in = d.i64();
  m.messages_out = d.i64();
  m.decode_errors = d.i64();
  m.dropped = d.i64();
  m.errors = d.i64();
  m.status = "degraded";
  m.last_error = "update rejected: chi2 = 41.3 > 12.6 (feature 17)";
  m.num_counters = 2;
  m.counter_names = {"bytes_dropped", "reconnects"};
  m.counter_values = {d.i64(), d.i64()};
  return m;
}

}  // namespace vimot_test

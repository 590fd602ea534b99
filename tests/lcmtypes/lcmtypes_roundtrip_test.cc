// Every vimot LCM message, filled with distinctive values
// (lcmtypes_samples.h), travels through a real in-memory LCM (memq://) to a
// typed subscriber and arrives with every field intact: scalars, fixed
// arrays, variable arrays, strings and nested structs. Each field is compared
// by name so a failure names the field; the final byte comparison catches a
// field added later but not listed here.
#include "lcmtypes_test_util.h"

using vimot_test::encode;
using vimot_test::publish_and_receive;
using vimot_test::vec;

TEST_CASE("imu_t round-trips through memq") {
  const vimot::imu_t s = vimot_test::sample_imu();

  const vimot::imu_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(vec(r.angular_velocity) == vec(s.angular_velocity));
  CHECK(vec(r.linear_acceleration) == vec(s.linear_acceleration));
  CHECK(encode(r) == encode(s));
}

TEST_CASE("image_t round-trips with padded rows and metadata") {
  const vimot::image_t s = vimot_test::sample_image();

  const vimot::image_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.width == s.width);
  CHECK(r.height == s.height);
  CHECK(r.row_stride == s.row_stride);
  CHECK(r.pixelformat == s.pixelformat);
  CHECK(r.size == s.size);
  CHECK(r.data == s.data);
  CHECK(r.nmetadata == s.nmetadata);
  REQUIRE(r.metadata.size() == s.metadata.size());
  for (std::size_t i = 0; i < s.metadata.size(); ++i) {
    INFO("metadata[" << i << "]");
    CHECK(r.metadata[i].key == s.metadata[i].key);
    CHECK(r.metadata[i].n == s.metadata[i].n);
    CHECK(r.metadata[i].value == s.metadata[i].value);
  }
  CHECK(encode(r) == encode(s));
}

namespace {
void check_features(const vimot::features_t& r, const vimot::features_t& s) {
  CHECK(r.utime == s.utime);
  CHECK(r.num_obs == s.num_obs);
  REQUIRE(r.obs.size() == s.obs.size());
  for (std::size_t i = 0; i < s.obs.size(); ++i) {
    INFO("obs[" << i << "]");
    CHECK(r.obs[i].feature_id == s.obs[i].feature_id);
    CHECK(r.obs[i].camera_id == s.obs[i].camera_id);
    CHECK(r.obs[i].u == s.obs[i].u);
    CHECK(r.obs[i].v == s.obs[i].v);
    CHECK(r.obs[i].x_norm == s.obs[i].x_norm);
    CHECK(r.obs[i].y_norm == s.obs[i].y_norm);
    CHECK(r.obs[i].is_target == s.obs[i].is_target);
  }
  CHECK(encode(r) == encode(s));
}
}  // namespace

TEST_CASE("features_t round-trips with static and target observations") {
  const vimot::features_t s = vimot_test::sample_features(5);
  check_features(publish_and_receive(s), s);
}

TEST_CASE("features_t round-trips with no observations") {
  const vimot::features_t s = vimot_test::sample_features(0);
  check_features(publish_and_receive(s), s);
}

TEST_CASE("mask_t round-trips") {
  const vimot::mask_t s = vimot_test::sample_mask();

  const vimot::mask_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.camera_id == s.camera_id);
  CHECK(r.width == s.width);
  CHECK(r.height == s.height);
  CHECK(r.size == s.size);
  CHECK(r.data == s.data);
  CHECK(encode(r) == encode(s));
}

TEST_CASE("target_box_t round-trips") {
  const vimot::target_box_t s = vimot_test::sample_target_box();

  const vimot::target_box_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.camera_id == s.camera_id);
  CHECK(r.raw_valid == s.raw_valid);
  CHECK(vec(r.raw_box) == vec(s.raw_box));
  CHECK(r.filtered_valid == s.filtered_valid);
  CHECK(vec(r.filtered_box) == vec(s.filtered_box));
  CHECK(vec(r.filtered_velocity) == vec(s.filtered_velocity));
  CHECK(vec(r.filtered_covariance) == vec(s.filtered_covariance));
  CHECK(r.frames_since_raw == s.frames_since_raw);
  CHECK(encode(r) == encode(s));
}

TEST_CASE("nav_state_t round-trips") {
  const vimot::nav_state_t s = vimot_test::sample_nav_state();

  const vimot::nav_state_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.updated == s.updated);
  CHECK(vec(r.q_GtoI) == vec(s.q_GtoI));
  CHECK(vec(r.p_IinG) == vec(s.p_IinG));
  CHECK(vec(r.v_IinG) == vec(s.v_IinG));
  CHECK(vec(r.bias_gyro) == vec(s.bias_gyro));
  CHECK(vec(r.bias_accel) == vec(s.bias_accel));
  CHECK(vec(r.covariance) == vec(s.covariance));
  CHECK(r.num_clones == s.num_clones);
  CHECK(r.num_slam_features == s.num_slam_features);
  CHECK(r.num_msckf_features == s.num_msckf_features);
  CHECK(encode(r) == encode(s));
}

TEST_CASE("target_state_t round-trips") {
  const vimot::target_state_t s = vimot_test::sample_target_state();

  const vimot::target_state_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.representation == s.representation);
  CHECK(vec(r.q_ItoT) == vec(s.q_ItoT));
  CHECK(vec(r.p_TinI) == vec(s.p_TinI));
  CHECK(vec(r.q_GtoT) == vec(s.q_GtoT));
  CHECK(vec(r.p_TinG) == vec(s.p_TinG));
  CHECK(vec(r.v_TinT) == vec(s.v_TinT));
  CHECK(vec(r.w_TinT) == vec(s.w_TinT));
  CHECK(vec(r.covariance) == vec(s.covariance));
  CHECK(r.num_target_points == s.num_target_points);
  CHECK(r.start_count == s.start_count);
  CHECK(encode(r) == encode(s));
}

TEST_CASE("target_state_t representation constants") {
  CHECK(vimot::target_state_t::GLOBAL == 0);
  CHECK(vimot::target_state_t::LOCAL == 1);
}

TEST_CASE("target_prediction_t round-trips") {
  const vimot::target_prediction_t s = vimot_test::sample_target_prediction();

  const vimot::target_prediction_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.prediction_utime == s.prediction_utime);
  CHECK(vec(r.q_GtoT) == vec(s.q_GtoT));
  CHECK(vec(r.p_TinG) == vec(s.p_TinG));
  CHECK(vec(r.q_ItoT) == vec(s.q_ItoT));
  CHECK(vec(r.p_TinI) == vec(s.p_TinI));
  CHECK(vec(r.covariance) == vec(s.covariance));
  CHECK(encode(r) == encode(s));
}

TEST_CASE("object_pose_t round-trips") {
  const vimot::object_pose_t s = vimot_test::sample_object_pose();

  const vimot::object_pose_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.valid == s.valid);
  CHECK(vec(r.q_OtoC) == vec(s.q_OtoC));
  CHECK(vec(r.p_OinC) == vec(s.p_OinC));
  CHECK(r.num_features == s.num_features);
  CHECK(r.reprojection_rms == s.reprojection_rms);
  CHECK(r.track_id == s.track_id);
  CHECK(encode(r) == encode(s));
}

TEST_CASE("scale_estimate_t round-trips") {
  const vimot::scale_estimate_t s = vimot_test::sample_scale_estimate();

  const vimot::scale_estimate_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.scale == s.scale);
  CHECK(r.accepted == s.accepted);
  CHECK(r.f_value == s.f_value);
  CHECK(vec(r.condition) == vec(s.condition));
  CHECK(vec(r.condition_ok) == vec(s.condition_ok));
  CHECK(r.failed_condition == s.failed_condition);
  CHECK(r.num_observations == s.num_observations);
  CHECK(encode(r) == encode(s));
}

TEST_CASE("metric_object_pose_t round-trips") {
  const vimot::metric_object_pose_t s = vimot_test::sample_metric_object_pose();

  const vimot::metric_object_pose_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.scale == s.scale);
  CHECK(vec(r.q_GtoO) == vec(s.q_GtoO));
  CHECK(vec(r.p_OinG) == vec(s.p_OinG));
  CHECK(encode(r) == encode(s));
}

TEST_CASE("ground_truth_t round-trips") {
  const vimot::ground_truth_t s = vimot_test::sample_ground_truth();

  const vimot::ground_truth_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(vec(r.q_GtoI) == vec(s.q_GtoI));
  CHECK(vec(r.p_IinG) == vec(s.p_IinG));
  CHECK(vec(r.v_IinG) == vec(s.v_IinG));
  CHECK(vec(r.w_IinI) == vec(s.w_IinI));
  CHECK(vec(r.a_IinG) == vec(s.a_IinG));
  CHECK(vec(r.bias_gyro) == vec(s.bias_gyro));
  CHECK(vec(r.bias_accel) == vec(s.bias_accel));
  CHECK(r.target_valid == s.target_valid);
  CHECK(vec(r.q_GtoT) == vec(s.q_GtoT));
  CHECK(vec(r.p_TinG) == vec(s.p_TinG));
  CHECK(vec(r.v_TinT) == vec(s.v_TinT));
  CHECK(vec(r.w_TinT) == vec(s.w_TinT));
  CHECK(encode(r) == encode(s));
}

TEST_CASE("heartbeat_t round-trips, including empty and non-ASCII strings") {
  vimot::heartbeat_t s = vimot_test::sample_heartbeat();
  s.last_error = "update rejected: χ² = 41.3 > 12.6";  // UTF-8 bytes pass unchanged

  vimot::heartbeat_t r = publish_and_receive(s);
  CHECK(r.utime == s.utime);
  CHECK(r.name == s.name);
  CHECK(r.pid == s.pid);
  CHECK(r.messages_in == s.messages_in);
  CHECK(r.messages_out == s.messages_out);
  CHECK(r.decode_errors == s.decode_errors);
  CHECK(r.dropped == s.dropped);
  CHECK(r.errors == s.errors);
  CHECK(r.status == s.status);
  CHECK(r.last_error == s.last_error);
  CHECK(r.counter_names == s.counter_names);
  CHECK(r.counter_values == s.counter_values);
  CHECK(encode(r) == encode(s));

  s.status = "ok";
  s.last_error = "";
  r = publish_and_receive(s);
  CHECK(r.status == "ok");
  CHECK(r.last_error.empty());
}

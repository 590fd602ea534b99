#include "common/process/lcm_conversions.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "common/math/quat.h"

namespace vimot {

namespace {

template <int N>
Eigen::Matrix<double, N, 1> read(const double (&a)[N], const char* what, int64_t utime) {
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) {
    if (!std::isfinite(a[i])) {
      throw std::invalid_argument(std::string(what) + " has a non-finite value at utime " + std::to_string(utime));
    }
    v(i) = a[i];
  }
  return v;
}

template <int N>
void write(const Eigen::Matrix<double, N, 1>& v, double (&a)[N]) {
  for (int i = 0; i < N; ++i) a[i] = v(i);
}

template <int N>
void write_matrix(const Eigen::Matrix<double, N, N>& m, double (&a)[N * N]) {
  for (int r = 0; r < N; ++r)
    for (int c = 0; c < N; ++c) a[r * N + c] = m(r, c);
}

template <int N>
Eigen::Matrix<double, N, N> read_matrix(const double (&a)[N * N], const char* what, int64_t utime) {
  Eigen::Matrix<double, N, N> m;
  for (int r = 0; r < N; ++r) {
    for (int c = 0; c < N; ++c) {
      const double v = a[r * N + c];
      if (!std::isfinite(v)) {
        throw std::invalid_argument(std::string(what) + " has a non-finite value at utime " + std::to_string(utime));
      }
      m(r, c) = v;
    }
  }
  return m;
}

}  // namespace

imu_t to_lcm(const ImuData& imu) {
  imu_t msg{};
  msg.utime = imu.utime;
  write<3>(imu.w_IinI, msg.angular_velocity);
  write<3>(imu.a_IinI, msg.linear_acceleration);
  return msg;
}

ImuData from_lcm(const imu_t& msg) {
  ImuData imu;
  imu.utime = msg.utime;
  imu.w_IinI = read<3>(msg.angular_velocity, "imu_t.angular_velocity", msg.utime);
  imu.a_IinI = read<3>(msg.linear_acceleration, "imu_t.linear_acceleration", msg.utime);
  return imu;
}

features_t to_lcm(const CameraFrame& frame) {
  features_t msg{};
  msg.utime = frame.utime;
  msg.num_obs = static_cast<int32_t>(frame.observations.size());
  msg.obs.reserve(frame.observations.size());
  for (const FeatureObservation& o : frame.observations) {
    feature_obs_t m{};
    m.feature_id = o.feature_id;
    m.camera_id = static_cast<int8_t>(o.camera_id);
    m.u = o.pixel.x();
    m.v = o.pixel.y();
    m.x_norm = o.normalized.x();
    m.y_norm = o.normalized.y();
    m.is_target = o.is_target;
    msg.obs.push_back(m);
  }
  return msg;
}

CameraFrame from_lcm(const features_t& msg) {
  if (msg.num_obs < 0 || static_cast<std::size_t>(msg.num_obs) != msg.obs.size()) {
    throw std::invalid_argument("features_t: num_obs " + std::to_string(msg.num_obs) + " does not match " +
                                std::to_string(msg.obs.size()) + " observations");
  }
  CameraFrame frame;
  frame.utime = msg.utime;
  frame.observations.reserve(msg.obs.size());
  for (const feature_obs_t& m : msg.obs) {
    if (!std::isfinite(m.u) || !std::isfinite(m.v) || !std::isfinite(m.x_norm) || !std::isfinite(m.y_norm)) {
      throw std::invalid_argument("features_t: feature " + std::to_string(m.feature_id) +
                                  " has non-finite coordinates at utime " + std::to_string(msg.utime));
    }
    if (m.camera_id < 0) {
      throw std::invalid_argument("features_t: negative camera_id " + std::to_string(m.camera_id));
    }
    FeatureObservation o;
    o.feature_id = m.feature_id;
    o.camera_id = m.camera_id;
    o.pixel = Eigen::Vector2d(m.u, m.v);
    o.normalized = Eigen::Vector2d(m.x_norm, m.y_norm);
    o.is_target = m.is_target;
    frame.observations.push_back(o);
  }
  return frame;
}

ground_truth_t to_lcm(const GroundTruth& t) {
  ground_truth_t msg{};
  msg.utime = t.utime;
  write<4>(t.q_GtoI, msg.q_GtoI);
  write<3>(t.p_IinG, msg.p_IinG);
  write<3>(t.v_IinG, msg.v_IinG);
  write<3>(t.w_IinI, msg.w_IinI);
  write<3>(t.a_IinG, msg.a_IinG);
  write<3>(t.bias_gyro, msg.bias_gyro);
  write<3>(t.bias_accel, msg.bias_accel);
  msg.target_valid = t.has_target;
  write<4>(t.q_GtoT, msg.q_GtoT);
  write<3>(t.p_TinG, msg.p_TinG);
  write<3>(t.v_TinT, msg.v_TinT);
  write<3>(t.w_TinT, msg.w_TinT);
  return msg;
}

GroundTruth from_lcm(const ground_truth_t& msg) {
  GroundTruth t;
  t.utime = msg.utime;
  t.q_GtoI = read<4>(msg.q_GtoI, "ground_truth_t.q_GtoI", msg.utime);
  t.p_IinG = read<3>(msg.p_IinG, "ground_truth_t.p_IinG", msg.utime);
  t.v_IinG = read<3>(msg.v_IinG, "ground_truth_t.v_IinG", msg.utime);
  t.w_IinI = read<3>(msg.w_IinI, "ground_truth_t.w_IinI", msg.utime);
  t.a_IinG = read<3>(msg.a_IinG, "ground_truth_t.a_IinG", msg.utime);
  t.bias_gyro = read<3>(msg.bias_gyro, "ground_truth_t.bias_gyro", msg.utime);
  t.bias_accel = read<3>(msg.bias_accel, "ground_truth_t.bias_accel", msg.utime);
  t.has_target = msg.target_valid;
  if (t.has_target) {
    t.q_GtoT = read<4>(msg.q_GtoT, "ground_truth_t.q_GtoT", msg.utime);
    t.p_TinG = read<3>(msg.p_TinG, "ground_truth_t.p_TinG", msg.utime);
    t.v_TinT = read<3>(msg.v_TinT, "ground_truth_t.v_TinT", msg.utime);
    t.w_TinT = read<3>(msg.w_TinT, "ground_truth_t.w_TinT", msg.utime);
  }
  return t;
}

nav_state_t to_lcm(const NavState& s) {
  nav_state_t msg{};
  msg.utime = s.utime;
  msg.updated = s.updated;
  write<4>(s.q_GtoI, msg.q_GtoI);
  write<3>(s.p_IinG, msg.p_IinG);
  write<3>(s.v_IinG, msg.v_IinG);
  write<3>(s.bias_gyro, msg.bias_gyro);
  write<3>(s.bias_accel, msg.bias_accel);
  for (int r = 0; r < 15; ++r)
    for (int c = 0; c < 15; ++c) msg.covariance[r * 15 + c] = s.covariance(r, c);
  msg.num_clones = s.num_clones;
  msg.num_slam_features = s.num_slam_features;
  msg.num_msckf_features = s.num_msckf_features;
  return msg;
}

NavState from_lcm(const nav_state_t& msg) {
  NavState s;
  s.utime = msg.utime;
  s.updated = msg.updated;
  s.q_GtoI = read<4>(msg.q_GtoI, "nav_state_t.q_GtoI", msg.utime);
  s.p_IinG = read<3>(msg.p_IinG, "nav_state_t.p_IinG", msg.utime);
  s.v_IinG = read<3>(msg.v_IinG, "nav_state_t.v_IinG", msg.utime);
  s.bias_gyro = read<3>(msg.bias_gyro, "nav_state_t.bias_gyro", msg.utime);
  s.bias_accel = read<3>(msg.bias_accel, "nav_state_t.bias_accel", msg.utime);
  for (int r = 0; r < 15; ++r) {
    for (int c = 0; c < 15; ++c) {
      const double v = msg.covariance[r * 15 + c];
      if (!std::isfinite(v)) {
        throw std::invalid_argument("nav_state_t.covariance has a non-finite value at utime " +
                                    std::to_string(msg.utime));
      }
      s.covariance(r, c) = v;
    }
  }
  s.num_clones = msg.num_clones;
  s.num_slam_features = msg.num_slam_features;
  s.num_msckf_features = msg.num_msckf_features;
  return s;
}

target_state_t to_lcm(const TargetStateEstimate& s) {
  target_state_t msg{};
  msg.utime = s.utime;
  msg.representation =
      s.representation == TargetFrame::kGlobal ? target_state_t::GLOBAL : target_state_t::LOCAL;
  write<4>(s.q_ItoT, msg.q_ItoT);
  write<3>(s.p_TinI, msg.p_TinI);
  write<4>(s.q_GtoT, msg.q_GtoT);
  write<3>(s.p_TinG, msg.p_TinG);
  write<3>(s.v_TinT, msg.v_TinT);
  write<3>(s.w_TinT, msg.w_TinT);
  write_matrix<12>(s.covariance, msg.covariance);
  msg.num_target_points = s.num_target_points;
  msg.start_count = s.start_count;
  return msg;
}

TargetStateEstimate from_lcm(const target_state_t& msg) {
  TargetStateEstimate s;
  s.utime = msg.utime;
  if (msg.representation == target_state_t::GLOBAL) {
    s.representation = TargetFrame::kGlobal;
  } else if (msg.representation == target_state_t::LOCAL) {
    s.representation = TargetFrame::kLocal;
  } else {
    throw std::invalid_argument("target_state_t: unknown representation " + std::to_string(msg.representation));
  }
  s.q_ItoT = read<4>(msg.q_ItoT, "target_state_t.q_ItoT", msg.utime);
  s.p_TinI = read<3>(msg.p_TinI, "target_state_t.p_TinI", msg.utime);
  s.q_GtoT = read<4>(msg.q_GtoT, "target_state_t.q_GtoT", msg.utime);
  s.p_TinG = read<3>(msg.p_TinG, "target_state_t.p_TinG", msg.utime);
  s.v_TinT = read<3>(msg.v_TinT, "target_state_t.v_TinT", msg.utime);
  s.w_TinT = read<3>(msg.w_TinT, "target_state_t.w_TinT", msg.utime);
  s.covariance = read_matrix<12>(msg.covariance, "target_state_t.covariance", msg.utime);
  if (msg.num_target_points < 0) {
    throw std::invalid_argument("target_state_t: negative num_target_points " +
                                std::to_string(msg.num_target_points));
  }
  s.num_target_points = msg.num_target_points;
  if (msg.start_count < 0) {
    throw std::invalid_argument("target_state_t: negative start_count " + std::to_string(msg.start_count));
  }
  s.start_count = msg.start_count;
  return s;
}

CameraTargetBox from_lcm(const target_box_t& msg) {
  CameraTargetBox b;
  b.utime = msg.utime;
  if (msg.camera_id != 0 && msg.camera_id != 1) {
    throw std::invalid_argument("target_box_t: camera_id " + std::to_string(msg.camera_id) + " is not 0 or 1");
  }
  b.camera_id = msg.camera_id;
  b.raw_valid = msg.raw_valid;
  b.filtered_valid = msg.filtered_valid;
  if (b.raw_valid) b.raw_box = read<4>(msg.raw_box, "target_box_t.raw_box", msg.utime);
  if (b.filtered_valid) b.filtered_box = read<4>(msg.filtered_box, "target_box_t.filtered_box", msg.utime);
  b.frames_since_raw = msg.frames_since_raw;
  return b;
}

target_prediction_t to_lcm(const TargetPosePrediction& p) {
  target_prediction_t msg{};
  msg.utime = p.utime;
  msg.prediction_utime = p.prediction_utime;
  write<4>(p.q_GtoT, msg.q_GtoT);
  write<3>(p.p_TinG, msg.p_TinG);
  write<4>(p.q_ItoT, msg.q_ItoT);
  write<3>(p.p_TinI, msg.p_TinI);
  write_matrix<6>(p.covariance, msg.covariance);
  return msg;
}

TargetPosePrediction from_lcm(const target_prediction_t& msg) {
  TargetPosePrediction p;
  p.utime = msg.utime;
  p.prediction_utime = msg.prediction_utime;
  p.q_GtoT = read<4>(msg.q_GtoT, "target_prediction_t.q_GtoT", msg.utime);
  p.p_TinG = read<3>(msg.p_TinG, "target_prediction_t.p_TinG", msg.utime);
  p.q_ItoT = read<4>(msg.q_ItoT, "target_prediction_t.q_ItoT", msg.utime);
  p.p_TinI = read<3>(msg.p_TinI, "target_prediction_t.p_TinI", msg.utime);
  p.covariance = read_matrix<6>(msg.covariance, "target_prediction_t.covariance", msg.utime);
  return p;
}

// ---- object tracker (issue 5) ----------------------------------------------

object_pose_t to_lcm(const ObjectPoseEstimate& e) {
  object_pose_t msg{};
  msg.utime = e.utime;
  msg.valid = e.valid;
  write<4>(e.q_OtoC, msg.q_OtoC);
  write<3>(e.pbar_OinC, msg.p_OinC);
  msg.num_features = e.num_features;
  msg.reprojection_rms = e.reprojection_rms_px;
  msg.track_id = e.track_id;
  return msg;
}

std::optional<frontend::Box> box_of(const target_box_t& m) {
  const double* b = m.filtered_valid ? m.filtered_box : (m.raw_valid ? m.raw_box : nullptr);
  if (b == nullptr) return std::nullopt;
  return frontend::Box{b[0], b[1], b[2], b[3]};
}

ObjectPoseEstimate from_lcm(const object_pose_t& msg) {
  ObjectPoseEstimate e;
  e.utime = msg.utime;
  e.valid = msg.valid;
  if (msg.num_features < 0) {
    throw std::invalid_argument("object_pose_t: negative num_features " + std::to_string(msg.num_features));
  }
  e.num_features = msg.num_features;
  e.track_id = msg.track_id;
  // An invalid pose's fields are meaningless and may be NaN: not checked.
  if (!e.valid) return e;
  e.q_OtoC = read<4>(msg.q_OtoC, "object_pose_t.q_OtoC", msg.utime);
  e.pbar_OinC = read<3>(msg.p_OinC, "object_pose_t.p_OinC", msg.utime);
  if (!std::isfinite(msg.reprojection_rms) || msg.reprojection_rms < 0.0) {
    throw std::invalid_argument("object_pose_t: bad reprojection_rms at utime " + std::to_string(msg.utime));
  }
  e.reprojection_rms_px = msg.reprojection_rms;
  return e;
}

// ---- scale estimator (issue 5) ---------------------------------------------

scale_estimate_t to_lcm(const scale::ScaleResult& r) {
  scale_estimate_t msg{};
  msg.utime = r.utime;
  msg.scale = r.scale;
  msg.accepted = r.accepted;
  msg.f_value = r.f_value;
  for (int k = 0; k < 3; ++k) {
    msg.condition[k] = r.condition[k];
    msg.condition_ok[k] = r.condition_ok[k];
  }
  msg.failed_condition = static_cast<int8_t>(r.failed_condition);
  msg.num_observations = r.num_observations;
  return msg;
}

metric_object_pose_t to_lcm(const scale::ObjectPoseInWorld& pose) {
  metric_object_pose_t msg{};
  msg.utime = pose.utime;
  msg.scale = pose.scale;
  write<4>(pose.q_GtoO, msg.q_GtoO);
  write<3>(pose.p_OinG, msg.p_OinG);
  return msg;
}

scale::ScaleResult from_lcm(const scale_estimate_t& msg) {
  scale::ScaleResult r;
  r.utime = msg.utime;
  r.scale = msg.scale;  // NaN allowed: s* undefined (see ScaleResult)
  r.accepted = msg.accepted;
  if (r.accepted && !(std::isfinite(msg.scale) && msg.scale > 0.0)) {
    throw std::invalid_argument("scale_estimate_t: accepted with scale " + std::to_string(msg.scale) + " at utime " +
                                std::to_string(msg.utime));
  }
  r.f_value = msg.f_value;
  for (int k = 0; k < 3; ++k) {
    r.condition[k] = msg.condition[k];
    r.condition_ok[k] = msg.condition_ok[k];
  }
  r.failed_condition = msg.failed_condition;
  r.num_observations = msg.num_observations;
  return r;
}

scale::ObjectPoseInWorld from_lcm(const metric_object_pose_t& msg) {
  scale::ObjectPoseInWorld p;
  p.utime = msg.utime;
  p.scale = msg.scale;
  if (!(std::isfinite(msg.scale) && msg.scale > 0.0)) {
    throw std::invalid_argument("metric_object_pose_t: scale " + std::to_string(msg.scale) + " at utime " +
                                std::to_string(msg.utime));
  }
  p.q_GtoO = quat_normalize(read<4>(msg.q_GtoO, "metric_object_pose_t.q_GtoO", msg.utime));
  p.R_OtoG = quat_to_rot(p.q_GtoO).transpose();
  p.p_OinG = read<3>(msg.p_OinG, "metric_object_pose_t.p_OinG", msg.utime);
  return p;
}

}  // namespace vimot

// ObjectPoseEstimate <-> vimot::object_pose_t (common/process/lcm_conversions).

#include <catch2/catch.hpp>

#include <cmath>

#include "common/process/lcm_conversions.h"

namespace vimot {
namespace {

TEST_CASE("object pose round trip through object_pose_t", "[object_tracker]") {
  ObjectPoseEstimate e;
  e.utime = 123456789;
  e.valid = true;
  e.q_OtoC = Eigen::Vector4d(0.1, -0.2, 0.3, 0.9).normalized();
  e.pbar_OinC = Eigen::Vector3d(0.2, -0.1, 1.0);
  e.num_features = 42;
  e.reprojection_rms_px = 0.7;
  e.track_id = 3;
  const object_pose_t msg = to_lcm(e);
  CHECK(msg.p_OinC[2] == 1.0);
  const ObjectPoseEstimate back = from_lcm(msg);
  CHECK(back.utime == e.utime);
  CHECK(back.valid);
  CHECK(back.q_OtoC == e.q_OtoC);
  CHECK(back.pbar_OinC == e.pbar_OinC);
  CHECK(back.num_features == 42);
  CHECK(back.reprojection_rms_px == 0.7);
  CHECK(back.track_id == 3);
}

TEST_CASE("object_pose_t: a valid pose must be finite, an invalid one is not read", "[object_tracker]") {
  object_pose_t msg = to_lcm(ObjectPoseEstimate{});
  msg.p_OinC[0] = std::nan("");
  CHECK_FALSE(from_lcm(msg).valid);
  msg.valid = true;
  CHECK_THROWS_AS(from_lcm(msg), std::invalid_argument);
  msg.p_OinC[0] = 0.0;
  msg.num_features = -1;
  CHECK_THROWS_AS(from_lcm(msg), std::invalid_argument);
}

}  // namespace
}  // namespace vimot

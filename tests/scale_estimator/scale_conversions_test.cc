// The scale estimator's LCM conversions (common/process/lcm_conversions.h)
// and the shipped config/scale_estimator.yaml.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/config/config.h"
#include "common/math/quat.h"
#include "common/process/lcm_conversions.h"
#include "procs/scale_estimator/scale_node.h"

using namespace vimot;

TEST_CASE("scale conversions: object pose in, estimate and metric pose out", "[scale]") {
  object_pose_t msg{};
  msg.utime = 123;
  msg.valid = true;
  const double q[4] = {0.0, 0.0, std::sin(0.25), std::cos(0.25)};
  for (int i = 0; i < 4; ++i) msg.q_OtoC[i] = q[i];
  msg.p_OinC[0] = 0.1;
  msg.p_OinC[1] = -0.2;
  msg.p_OinC[2] = 1.0;
  msg.num_features = 40;
  ObjectPoseEstimate p = from_lcm(msg);
  CHECK(p.utime == 123);
  CHECK(p.valid);
  CHECK(p.q_OtoC == Eigen::Vector4d(q[0], q[1], q[2], q[3]));
  CHECK(p.pbar_OinC == Eigen::Vector3d(0.1, -0.2, 1.0));
  CHECK(p.num_features == 40);
  msg.p_OinC[1] = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS_AS(from_lcm(msg), std::invalid_argument);
  // An invalid pose's fields are meaningless: not read, not checked.
  msg.valid = false;
  p = from_lcm(msg);
  CHECK(!p.valid);
  CHECK(p.pbar_OinC.allFinite());

  scale::ScaleResult r;
  r.utime = 77;
  r.scale = 2.5;
  r.accepted = false;
  r.f_value = 1e-3;
  r.condition = {{1e-3, 2e-2, 3e-4}};
  r.condition_ok = {{false, true, false}};
  r.failed_condition = 1;
  r.num_observations = 800;
  const scale_estimate_t e = to_lcm(r);
  CHECK(e.utime == 77);
  CHECK(e.scale == 2.5);
  CHECK(!e.accepted);
  CHECK(e.f_value == 1e-3);
  CHECK(e.condition[1] == 2e-2);
  CHECK(e.condition_ok[1]);
  CHECK(!e.condition_ok[2]);
  CHECK(e.failed_condition == 1);
  CHECK(e.num_observations == 800);

  scale::ObjectPoseInWorld w;
  w.utime = 88;
  w.scale = 2.5;
  w.q_GtoO = Eigen::Vector4d(q[0], q[1], q[2], q[3]);
  w.p_OinG = Eigen::Vector3d(1, 2, 3);
  const metric_object_pose_t m = to_lcm(w);
  CHECK(m.utime == 88);
  CHECK(m.scale == 2.5);
  CHECK(m.q_GtoO[3] == q[3]);
  CHECK(m.p_OinG[2] == 3.0);
}

TEST_CASE("scale config: the shipped file loads cam0's extrinsics and the thresholds", "[scale]") {
  const Config cfg = Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/scale_estimator.yaml");
  const ScaleNodeOptions o = scale_node_options_from_config(cfg);
  // EuRoC cam0 (config/euroc_stereo.yaml): T_BS maps C to I; R_ItoC = R_BS^T.
  CHECK_THAT(o.camera.R_ItoC(1, 0), Catch::Matchers::WithinAbs(-0.999880929698, 1e-12));
  CHECK_THAT(o.camera.R_ItoC.determinant(), Catch::Matchers::WithinAbs(1.0, 1e-6));
  CHECK(o.estimator.window_size == 800);
  CHECK(o.estimator.rho_t1 == 1e-4);
  CHECK(o.max_pending == 60);
}

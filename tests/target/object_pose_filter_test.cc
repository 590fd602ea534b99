// ObjectPoseFilter (common/target/object_pose_filter.h) on a synthetic rigid
// body with constant local velocities seen by a fixed camera: noisy poses
// drawn from the filter's own measurement covariance, so with a negligible
// process noise the filter's model is exact and its NEES must be the state
// dimension. Also: χ² gate, re-initialisation, refused input.
#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Cholesky>

#include "common/math/quat.h"
#include "common/target/object_pose_filter.h"

using namespace vimot;
using namespace vimot::target;

namespace {

constexpr int64_t kStart = 1'700'000'000'000'000;  // µs: large absolute utimes
constexpr int64_t kStep = 50'000;                  // 20 Hz

// Camera at the origin looking along x of G (C's z), C's x = −y of G, C's y = −z of G.
Eigen::Matrix3d camera_R_CtoG() { return (Eigen::Matrix3d() << 0, 0, 1, -1, 0, 0, 0, -1, 0).finished(); }

TargetValue initial_truth() {
  TargetValue x;
  x.q_RtoT = quat_normalize(Eigen::Vector4d(0.1, -0.2, 0.3, 0.9));
  x.p_TinR = Eigen::Vector3d(3.0, 0.2, -0.3);
  x.v_TinT = Eigen::Vector3d(0.3, -0.1, 0.05);
  x.w_TinT = Eigen::Vector3d(0.05, -0.03, 0.2);
  return x;
}

ObjectPoseFilterOptions test_options() {
  ObjectPoseFilterOptions o;
  o.noise = TargetNoise::isotropic(1e-4, 1e-4);  // the truth has constant velocities
  return o;
}

ObjectPoseMeasurement exact_measurement(int64_t utime, const TargetValue& x) {
  ObjectPoseMeasurement z;
  z.utime = utime;
  z.q_GtoO = x.q_RtoT;
  z.p_OinG = x.p_TinR;
  z.R_CtoG = camera_R_CtoG();
  z.p_OinC = z.R_CtoG.transpose() * x.p_TinR;
  return z;
}

// z = truth ⊞ n, n ~ N(0, R(truth)).
ObjectPoseMeasurement noisy_measurement(int64_t utime, const TargetValue& x, const ObjectPoseFilterOptions& o,
                                        std::mt19937_64* rng) {
  ObjectPoseMeasurement z = exact_measurement(utime, x);
  const Matrix6d L = Matrix6d(measurement_covariance(o, z).llt().matrixL());
  std::normal_distribution<double> n01;
  Vector6d e;
  for (int i = 0; i < 6; ++i) e(i) = n01(*rng);
  const PoseValue pz = boxplus(x.pose(), Vector6d(L * e));
  z.q_GtoO = pz.q;
  z.p_OinG = pz.p;
  return z;
}

struct Trajectory {
  std::vector<int64_t> utimes;
  std::vector<TargetValue> truth;
};

Trajectory constant_velocity_truth(int steps) {
  Trajectory t;
  TargetValue x = initial_truth();
  for (int k = 0; k < steps; ++k) {
    t.utimes.push_back(kStart + k * kStep);
    t.truth.push_back(x);
    TargetValue next;
    propagate_global(x, kStep * 1e-6, TargetNoise::isotropic(0.0, 0.0), &next, nullptr, nullptr);
    x = next;
  }
  return t;
}

}  // namespace

TEST_CASE("object_pose_filter: measurement covariance from the camera geometry", "[target]") {
  ObjectPoseFilterOptions o;
  o.k_lateral = 0.01;
  o.k_depth = 0.02;
  o.sigma_theta_C = Eigen::Vector3d(0.01, 0.02, 0.03);
  ObjectPoseMeasurement z;
  z.R_CtoG = camera_R_CtoG();
  z.p_OinC = Eigen::Vector3d(0.0, 0.0, 2.0);  // d = 2: lateral 0.02 m, depth 0.02·4 = 0.08 m
  z.q_GtoO = rot_to_quat(z.R_CtoG.transpose());  // O = C: orientation σ unrotated
  const Matrix6d R = measurement_covariance(o, z);
  // Depth is C's z = G's x; C's x, y are G's −y, −z.
  CHECK_THAT(R(3, 3), Catch::Matchers::WithinRel(0.08 * 0.08, 1e-12));
  CHECK_THAT(R(4, 4), Catch::Matchers::WithinRel(0.02 * 0.02, 1e-12));
  CHECK_THAT(R(5, 5), Catch::Matchers::WithinRel(0.02 * 0.02, 1e-12));
  CHECK_THAT(R(0, 0), Catch::Matchers::WithinRel(1e-4, 1e-12));
  CHECK_THAT(R(2, 2), Catch::Matchers::WithinRel(9e-4, 1e-12));
  CHECK(R.topRightCorner<3, 3>().isZero());
  CHECK(R.bottomRightCorner<3, 3>().isApprox(Eigen::Vector3d(0.0064, 0.0004, 0.0004).asDiagonal().toDenseMatrix()));
}

TEST_CASE("object_pose_filter: smooths below the measurement noise, consistent NEES over seeds", "[target]") {
  const ObjectPoseFilterOptions o = test_options();
  const Trajectory traj = constant_velocity_truth(200);  // 10 s
  const int seeds = 40;
  double nees_sum = 0.0, nees_pose_sum = 0.0;
  int nees_n = 0;
  Eigen::Vector3d err_sq_filter = Eigen::Vector3d::Zero(), err_sq_meas = Eigen::Vector3d::Zero();
  int err_n = 0;
  for (int seed = 1; seed <= seeds; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(seed));
    ObjectPoseFilter f(o);
    for (std::size_t k = 0; k < traj.utimes.size(); ++k) {
      const ObjectPoseMeasurement z = noisy_measurement(traj.utimes[k], traj.truth[k], o, &rng);
      const ObjectFilterStatus st = f.add(z);  // 5 % of the poses are gated: that is the gate's level
      REQUIRE((is_accepted(st) || st == ObjectFilterStatus::kRejectedOutlier));
      const Vector12d e = boxminus(traj.truth[k], f.value());
      nees_sum += e.dot(f.covariance().ldlt().solve(e));
      nees_pose_sum += e.head<6>().dot(f.covariance().topLeftCorner<6, 6>().ldlt().solve(e.head<6>()));
      ++nees_n;
      if (k >= 40) {  // after 2 s: the velocities have converged
        const Eigen::Matrix3d R_GtoC = z.R_CtoG.transpose();
        err_sq_filter += (R_GtoC * e.segment<3>(3)).cwiseAbs2();
        err_sq_meas += (R_GtoC * (z.p_OinG - traj.truth[k].p_TinR)).cwiseAbs2();
        ++err_n;
      }
    }
    CHECK(f.stats().outliers <= 25);  // 5 % expected of 200
    CHECK(f.stats().reinitializations == 0);
  }
  const double nees = nees_sum / nees_n, nees_pose = nees_pose_sum / nees_n;
  const Eigen::Vector3d std_filter = (err_sq_filter / err_n).cwiseSqrt(), std_meas = (err_sq_meas / err_n).cwiseSqrt();
  INFO("NEES 12-dof " << nees << ", pose 6-dof " << nees_pose << "; position error std in C (x y depth): filter "
                      << std_filter.transpose() << ", measurement " << std_meas.transpose());
  CHECK(nees > 0.5 * 12);
  CHECK(nees < 2.0 * 12);
  CHECK(nees_pose > 0.5 * 6);
  CHECK(nees_pose < 2.0 * 6);
  // Depth noise 3.6 cm at 3 m: the filter must remove most of it.
  CHECK(std_filter(2) < 0.5 * std_meas(2));
  CHECK(std_filter(0) < 0.7 * std_meas(0));
  CHECK(std_filter(1) < 0.7 * std_meas(1));
}

TEST_CASE("object_pose_filter: χ² gate rejects a gross outlier, the state stays on the truth", "[target]") {
  const ObjectPoseFilterOptions o = test_options();
  const Trajectory traj = constant_velocity_truth(100);
  std::mt19937_64 rng(7);
  ObjectPoseFilter f(o);
  for (std::size_t k = 0; k < 99; ++k) {
    const ObjectFilterStatus st = f.add(noisy_measurement(traj.utimes[k], traj.truth[k], o, &rng));
    REQUIRE((st == ObjectFilterStatus::kInitialized || st == ObjectFilterStatus::kUpdated ||
             st == ObjectFilterStatus::kRejectedOutlier));
  }
  const int64_t outliers = f.stats().outliers;
  ObjectPoseMeasurement bad = exact_measurement(traj.utimes[99], traj.truth[99]);
  bad.p_OinG += Eigen::Vector3d(0.0, 0.5, 0.0);  // 0.5 m lateral, σ ≈ 1 cm
  CHECK(f.add(bad) == ObjectFilterStatus::kRejectedOutlier);
  CHECK(f.stats().outliers == outliers + 1);
  CHECK(f.last_nis() > 1000.0);
  CHECK(f.utime() == traj.utimes[99]);  // predicted to the outlier's time, not corrected by it
  CHECK((f.value().p_TinR - traj.truth[99].p_TinR).norm() < 0.03);
}

TEST_CASE("object_pose_filter: re-initialises after consecutive rejections and after a gap", "[target]") {
  ObjectPoseFilterOptions o = test_options();
  o.max_consecutive_rejections = 3;
  const Trajectory traj = constant_velocity_truth(60);
  ObjectPoseFilter f(o);
  for (std::size_t k = 0; k < 50; ++k) REQUIRE(is_accepted(f.add(exact_measurement(traj.utimes[k], traj.truth[k]))));
  // The object "teleports" 2 m (e.g. a wrong scale): two rejections, then the third re-initialises.
  const Eigen::Vector3d jump(0.0, 2.0, 0.0);
  for (std::size_t k = 50; k < 52; ++k) {
    ObjectPoseMeasurement z = exact_measurement(traj.utimes[k], traj.truth[k]);
    z.p_OinG += jump;
    CHECK(f.add(z) == ObjectFilterStatus::kRejectedOutlier);
  }
  ObjectPoseMeasurement z = exact_measurement(traj.utimes[52], traj.truth[52]);
  z.p_OinG += jump;
  CHECK(f.add(z) == ObjectFilterStatus::kReinitialized);
  CHECK(f.stats().reinitializations == 1);
  CHECK(f.value().p_TinR.isApprox(z.p_OinG));
  CHECK(f.value().v_TinT.isZero());
  CHECK(f.covariance()(6, 6) == o.init_sigma_v * o.init_sigma_v);
  z = exact_measurement(traj.utimes[53], traj.truth[53]);
  z.p_OinG += jump;
  CHECK(f.add(z) == ObjectFilterStatus::kUpdated);  // the counter restarted

  // A gap above max_gap_s: re-initialised, not extrapolated.
  const int64_t later = traj.utimes[53] + static_cast<int64_t>(1.5e6);
  CHECK(f.add(exact_measurement(later, traj.truth[0])) == ObjectFilterStatus::kReinitialized);
  CHECK(f.stats().gap_reinitializations == 1);
  CHECK(f.value().p_TinR.isApprox(traj.truth[0].p_TinR));
}

TEST_CASE("object_pose_filter: time going back, duplicates and non-finite input are counted, never used",
          "[target]") {
  const ObjectPoseFilterOptions o = test_options();
  const Trajectory traj = constant_velocity_truth(10);
  ObjectPoseFilter f(o);
  CHECK(f.add(exact_measurement(traj.utimes[0], traj.truth[0])) == ObjectFilterStatus::kInitialized);
  CHECK(f.add(exact_measurement(traj.utimes[1], traj.truth[1])) == ObjectFilterStatus::kUpdated);
  const TargetValue before = f.value();
  const Matrix12d P_before = f.covariance();
  CHECK(f.add(exact_measurement(traj.utimes[1], traj.truth[1])) == ObjectFilterStatus::kRejectedTimeOrder);
  CHECK(f.add(exact_measurement(traj.utimes[0], traj.truth[0])) == ObjectFilterStatus::kRejectedTimeOrder);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  ObjectPoseMeasurement z = exact_measurement(traj.utimes[2], traj.truth[2]);
  z.p_OinG.x() = nan;
  CHECK(f.add(z) == ObjectFilterStatus::kRejectedInvalid);
  z = exact_measurement(traj.utimes[2], traj.truth[2]);
  z.q_GtoO = Eigen::Vector4d::Zero();
  CHECK(f.add(z) == ObjectFilterStatus::kRejectedInvalid);
  z = exact_measurement(traj.utimes[2], traj.truth[2]);
  z.R_CtoG(0, 0) = std::numeric_limits<double>::infinity();
  CHECK(f.add(z) == ObjectFilterStatus::kRejectedInvalid);
  z = exact_measurement(traj.utimes[2], traj.truth[2]);
  z.scale = 0.0;  // the held scale's ratio would divide by it
  CHECK(f.add(z) == ObjectFilterStatus::kRejectedInvalid);
  CHECK(f.stats().duplicates == 1);
  CHECK(f.stats().backwards == 1);
  CHECK(f.stats().invalid == 4);
  CHECK(f.utime() == traj.utimes[1]);
  CHECK(f.value().to_vector() == before.to_vector());
  CHECK(f.covariance() == P_before);
  CHECK(f.add(exact_measurement(traj.utimes[2], traj.truth[2])) == ObjectFilterStatus::kUpdated);

  f.reset();
  CHECK(!f.initialized());
  // After reset the time order restarts (a new object frame).
  CHECK(f.add(exact_measurement(traj.utimes[0], traj.truth[0])) == ObjectFilterStatus::kInitialized);
  CHECK(f.stats().initializations == 2);
}

TEST_CASE("object_pose_filter: prediction follows the motion model", "[target]") {
  const ObjectPoseFilterOptions o = test_options();
  const Trajectory traj = constant_velocity_truth(120);
  ObjectPoseFilter f(o);
  for (std::size_t k = 0; k < 100; ++k) REQUIRE(is_accepted(f.add(exact_measurement(traj.utimes[k], traj.truth[k]))));
  const TargetPrediction p = f.predict((traj.utimes[110] - traj.utimes[99]) * 1e-6);
  CHECK((p.x.p_TinR - traj.truth[110].p_TinR).norm() < 1e-3);
  CHECK(p.P.trace() > f.covariance().trace());
  CHECK_THROWS_AS(ObjectPoseFilter([] {
                    ObjectPoseFilterOptions bad;
                    bad.k_depth = 0.0;
                    return bad;
                  }()),
                  std::invalid_argument);
}

// The tracker's slowly varying errors as the filter models them: a constant
// orientation offset θ_b and origin offset p_b of O, and the held scale's
// relative error ε = ŝ/s − 1 (z_p = p + R_OtoG p_b + ε (p − p_CinG)), drawn from the
// priors per seed, plus white noise. The held scale ŝ also steps every 2 s
// (a new accepted estimate), which moves the metric poses and ε by a known
// ratio. With the bias states the pose NEES is the dimension; the 12-state
// filter on the same data averages the biases down as if they were white
// and is overconfident (negative control).
TEST_CASE("object_pose_filter: bias states keep the NEES consistent under offsets and held-scale steps",
          "[target]") {
  ObjectPoseFilterOptions o = test_options();
  o.bias_sigma_theta = 0.02;
  o.bias_sigma_position = 0.02;
  o.scale_sigma = 0.01;
  ObjectPoseFilterOptions plain = o;
  plain.bias_sigma_theta = plain.bias_sigma_position = plain.scale_sigma = 0.0;
  const Trajectory traj = constant_velocity_truth(200);
  const Eigen::Vector3d p_CinG = Eigen::Vector3d::Zero();  // the test camera sits at the origin
  double nees_bias = 0.0, nees_plain = 0.0;
  int n = 0;
  for (int seed = 1; seed <= 40; ++seed) {
    std::mt19937_64 rng(static_cast<uint64_t>(1000 + seed));
    std::normal_distribution<double> n01;
    const Eigen::Vector3d theta_b(0.02 * n01(rng), 0.02 * n01(rng), 0.02 * n01(rng));
    const Eigen::Vector3d p_b(0.02 * n01(rng), 0.02 * n01(rng), 0.02 * n01(rng));
    const double s_true = 2.0;
    double s_held = s_true * (1.0 + 0.01 * n01(rng));  // ε = ŝ/s − 1 ~ N(0, 0.01²)
    ObjectPoseFilter with_bias(o), without(plain);
    for (std::size_t k = 0; k < traj.utimes.size(); ++k) {
      if (k > 0 && k % 40 == 0) s_held *= 1.0 + 0.003 * n01(rng);  // a new accepted scale
      const TargetValue& x = traj.truth[k];
      ObjectPoseMeasurement z = noisy_measurement(traj.utimes[k], x, o, &rng);
      const Eigen::Matrix3d R_OtoG = quat_to_rot(x.q_RtoT).transpose();
      z.q_GtoO = boxplus(PoseValue{z.q_GtoO, z.p_OinG}, (Vector6d() << theta_b, Eigen::Vector3d::Zero()).finished()).q;
      // Metric position with the held scale: p_C + (ŝ/s)(p + R_OtoG p_b − p_C) + noise.
      z.p_OinG = p_CinG + (s_held / s_true) * (z.p_OinG + R_OtoG * p_b - p_CinG);
      z.p_OinC = z.R_CtoG.transpose() * (z.p_OinG - p_CinG);
      z.scale = s_held;
      REQUIRE((is_accepted(with_bias.add(z)) || with_bias.stats().outliers > 0));
      without.add(z);
      if (k < 40) continue;
      const Vector6d e = boxminus(x, with_bias.value()).head<6>();
      nees_bias += e.dot(with_bias.covariance().topLeftCorner<6, 6>().ldlt().solve(e));
      const Vector6d e_plain = boxminus(x, without.value()).head<6>();
      nees_plain += e_plain.dot(without.covariance().topLeftCorner<6, 6>().ldlt().solve(e_plain));
      ++n;
    }
  }
  nees_bias /= n;
  nees_plain /= n;
  INFO("pose NEES (6 dof): with bias states " << nees_bias << ", 12-state filter " << nees_plain);
  CHECK(nees_bias > 0.5 * 6);
  CHECK(nees_bias < 2.0 * 6);
  CHECK(nees_plain > 3.0 * 6);
}

// A new held scale moves every later metric pose by (ŝ_new/ŝ_old − 1)(z_p −
// p_C): the filter shifts ε by the known ratio, so the position estimate
// does not jump (by 2 % of 3 m = 6 cm if the ratio were ignored) and no
// pose is gated; what remains is the start-up transient (v starts at 0).
TEST_CASE("object_pose_filter: a held-scale step moves ε, not the position", "[target]") {
  ObjectPoseFilterOptions o = test_options();
  o.scale_sigma = 0.01;
  const Trajectory traj = constant_velocity_truth(100);
  ObjectPoseFilter f(o);
  for (std::size_t k = 0; k < 100; ++k) {
    ObjectPoseMeasurement z = exact_measurement(traj.utimes[k], traj.truth[k]);
    z.scale = 2.0;
    if (k >= 60) {  // ŝ 2 % larger: the metric position 2 % further from the camera at the origin
      z.scale = 2.04;
      z.p_OinG *= 1.02;
      z.p_OinC *= 1.02;
    }
    REQUIRE(is_accepted(f.add(z)));
  }
  CHECK(f.stats().outliers == 0);
  CHECK((f.value().p_TinR - traj.truth[99].p_TinR).norm() < 1e-3);
  CHECK_THAT(f.biases()(6), Catch::Matchers::WithinAbs(0.02, 1e-4));  // ε = ŝ/s − 1 with s = 2
}

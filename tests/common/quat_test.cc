// Quaternion / SO(3) helpers checked against independent formulas: the
// axis-angle matrix written out by hand, Eigen's own Hamilton quaternion,
// matrix products, and finite differences for the Jacobians.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>

#include "common/math/quat.h"

using namespace vimot;

namespace {
Eigen::Vector4d random_quat(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return quat_normalize(Eigen::Vector4d(n(rng), n(rng), n(rng), n(rng)));
}
Eigen::Vector3d random_vec(std::mt19937& rng, double scale = 1.0) {
  std::normal_distribution<double> n(0.0, scale);
  return Eigen::Vector3d(n(rng), n(rng), n(rng));
}
}  // namespace

TEST_CASE("JPL quaternion of a rotation about z is the transposed axis-angle matrix") {
  // JPL: angle θ about axis k gives q = [k sin(θ/2); cos(θ/2)] and R = exp(-θ[k x]).
  const double th = 0.7;
  const Eigen::Vector4d q(0.0, 0.0, std::sin(th / 2), std::cos(th / 2));
  Eigen::Matrix3d Rz;  // written out by hand: passive rotation by θ about z
  Rz << std::cos(th), std::sin(th), 0, -std::sin(th), std::cos(th), 0, 0, 0, 1;
  CHECK((quat_to_rot(q) - Rz).norm() < 1e-14);
  CHECK((exp_so3(Eigen::Vector3d(0, 0, -th)) - Rz).norm() < 1e-14);
}

TEST_CASE("JPL matrix equals the transpose of Eigen's Hamilton matrix of the same numbers") {
  std::mt19937 rng(1);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector4d q = random_quat(rng);
    const Eigen::Quaterniond h(q(3), q(0), q(1), q(2));
    CHECK((quat_to_rot(q) - h.toRotationMatrix().transpose()).norm() < 1e-13);
    CHECK((quat_to_rot(q) * quat_to_rot(q).transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-13);
    CHECK(std::abs(quat_to_rot(q).determinant() - 1.0) < 1e-13);
  }
}

TEST_CASE("rot_to_quat inverts quat_to_rot, including near 180 degrees") {
  std::mt19937 rng(2);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector4d q = random_quat(rng);
    CHECK((rot_to_quat(quat_to_rot(q)) - q).norm() < 1e-12);
  }
  const Eigen::Vector4d near_pi = quat_normalize(Eigen::Vector4d(0.6, 0.8, 0.0, 1e-9));
  CHECK((quat_to_rot(rot_to_quat(quat_to_rot(near_pi))) - quat_to_rot(near_pi)).norm() < 1e-12);
}

TEST_CASE("quaternion product composes like the matrices, inverse is the transpose") {
  std::mt19937 rng(3);
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector4d q = random_quat(rng), p = random_quat(rng);
    CHECK((quat_to_rot(quat_multiply(q, p)) - quat_to_rot(q) * quat_to_rot(p)).norm() < 1e-13);
    CHECK((quat_to_rot(quat_inverse(q)) - quat_to_rot(q).transpose()).norm() < 1e-13);
  }
}

TEST_CASE("exp and log of SO(3) are inverse; skew and vee are inverse") {
  std::mt19937 rng(4);
  for (int i = 0; i < 50; ++i) {
    Eigen::Vector3d th = random_vec(rng);
    if (th.norm() > 3.0) th *= 3.0 / th.norm();
    CHECK((log_so3(exp_so3(th)) - th).norm() < 1e-12);
    CHECK((vee(skew(th)) - th).norm() < 1e-15);
    CHECK((skew(th) * Eigen::Vector3d(1, 2, 3) - th.cross(Eigen::Vector3d(1, 2, 3))).norm() < 1e-15);
    // Rodrigues against Eigen's AngleAxis (a Hamilton, active rotation).
    CHECK((exp_so3(th) - Eigen::AngleAxisd(th.norm(), th.normalized()).toRotationMatrix()).norm() < 1e-13);
  }
  CHECK((exp_so3(Eigen::Vector3d(1e-9, 0, 0)) - Eigen::Matrix3d::Identity()).norm() < 1e-8);
}

TEST_CASE("left and right Jacobians of SO(3) match finite differences") {
  std::mt19937 rng(5);
  const double eps = 1e-6;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d th = random_vec(rng);
    Eigen::Matrix3d Jl_fd, Jr_fd;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = eps * Eigen::Vector3d::Unit(k);
      Jl_fd.col(k) = log_so3(exp_so3(th + d) * exp_so3(th).transpose()) / eps;
      Jr_fd.col(k) = log_so3(exp_so3(th).transpose() * exp_so3(th + d)) / eps;
    }
    CHECK((jl_so3(th) - Jl_fd).norm() < 1e-5);
    CHECK((jr_so3(th) - Jr_fd).norm() < 1e-5);
  }
}

TEST_CASE("quaternion kinematics: q_dot = 0.5 Omega(w) q matches R_dot = -[w x] R") {
  std::mt19937 rng(6);
  const Eigen::Vector4d q = random_quat(rng);
  const Eigen::Vector3d w = random_vec(rng);
  const double dt = 1e-7;
  const Eigen::Vector4d q_next = quat_normalize(q + 0.5 * dt * omega_matrix(w) * q);
  const Eigen::Matrix3d Rdot_fd = (quat_to_rot(q_next) - quat_to_rot(q)) / dt;
  CHECK((Rdot_fd - (-skew(w) * quat_to_rot(q))).norm() < 1e-5);
}

TEST_CASE("boxplus applies a left error: R = exp(-dtheta) R_hat") {
  std::mt19937 rng(7);
  const Eigen::Vector4d q = random_quat(rng);
  const Eigen::Vector3d d = random_vec(rng, 0.3);
  CHECK((quat_to_rot(quat_boxplus(q, d)) - exp_so3(-d) * quat_to_rot(q)).norm() < 1e-13);
  CHECK((quat_to_rot(small_angle_quat(d)) - exp_so3(-d)).norm() < 1e-13);
}

TEST_CASE("TUM Hamilton body-to-world quaternion maps to JPL q_GtoI") {
  std::mt19937 rng(8);
  const Eigen::Vector4d h = random_quat(rng);  // x y z w as in a TUM line
  const Eigen::Quaterniond eig(h(3), h(0), h(1), h(2));
  const Eigen::Matrix3d R_ItoG = eig.toRotationMatrix();
  CHECK((quat_to_rot(hamilton_ItoG_to_jpl_GtoI(h)) - R_ItoG.transpose()).norm() < 1e-13);
  CHECK((jpl_GtoI_to_hamilton_ItoG(hamilton_ItoG_to_jpl_GtoI(h)) - h).norm() < 1e-13);
}

TEST_CASE("quat_normalize rejects what is not a rotation") {
  CHECK_THROWS_AS(quat_normalize(Eigen::Vector4d::Zero()), std::invalid_argument);
  CHECK_THROWS_AS(quat_normalize(Eigen::Vector4d(NAN, 0, 0, 1)), std::invalid_argument);
  CHECK(rotation_angle_between(exp_so3(Eigen::Vector3d(0, 0, 0.3)), Eigen::Matrix3d::Identity()) ==
        Approx(0.3).epsilon(1e-12));
}

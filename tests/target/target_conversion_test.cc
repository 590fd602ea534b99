#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>

#include "common/math/quat.h"
#include "common/target/target_conversion.h"
#include "target_test_util.h"

using namespace vimot;
using namespace vimot::target;
using vimot::target::test::central_diff;
using vimot::target::test::rel_err;

TEST_CASE("local/global conversions round-trip and match the frame algebra", "[target]") {
  const PoseValue pose = imu_pose(test::sample_imu());
  const TargetValue xl = test::sample_target();
  const TargetValue xg = local_to_global(pose, xl);
  // Independent check: a target point expressed both ways.
  const Eigen::Vector3d p_FinT(0.3, -0.2, 0.5);
  const Eigen::Vector3d p_FinI = xl.R_RtoT().transpose() * p_FinT + xl.p_TinR;
  const Eigen::Vector3d p_FinG = xg.R_RtoT().transpose() * p_FinT + xg.p_TinR;
  CHECK((pose.R().transpose() * p_FinI + pose.p - p_FinG).norm() < 1e-12);
  const TargetValue back = global_to_local(pose, xg);
  CHECK(boxminus(back, xl).norm() < 1e-12);
}

TEST_CASE("conversion Jacobians equal central finite differences", "[target]") {
  const PoseValue pose = imu_pose(test::sample_imu());
  const TargetValue x = test::sample_target();
  for (int dir = 0; dir < 2; ++dir) {
    const bool to_global = dir == 0;
    auto conv = [&](const PoseValue& p, const TargetValue& t) {
      return to_global ? local_to_global(p, t) : global_to_local(p, t);
    };
    Matrix12x6d Jp;
    Matrix12d Jt;
    const TargetValue y = to_global ? local_to_global(pose, x, &Jp, &Jt) : global_to_local(pose, x, &Jp, &Jt);
    const Eigen::MatrixXd Np = central_diff(6, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return boxminus(conv(boxplus(pose, Vector6d(d)), x), y);
    });
    const Eigen::MatrixXd Nt = central_diff(12, [&](const Eigen::VectorXd& d) -> Eigen::VectorXd {
      return boxminus(conv(pose, boxplus(x, Vector12d(d))), y);
    });
    INFO("direction " << (to_global ? "local->global" : "global->local"));
    CHECK(rel_err(Jp, Np) < 1e-8);
    CHECK(rel_err(Jt, Nt) < 1e-8);
  }
}

TEST_CASE("conversion covariances are J P J^T and invert each other", "[target]") {
  const PoseValue pose = imu_pose(test::sample_imu());
  const TargetValue xl = test::sample_target();
  Eigen::Matrix<double, 18, 18> A = Eigen::Matrix<double, 18, 18>::Random() * 0.1;
  Eigen::Matrix<double, 18, 18> P = A * A.transpose() + 1e-3 * Eigen::Matrix<double, 18, 18>::Identity();
  const Matrix12d Pg = local_to_global_covariance(pose, xl, P);
  CHECK((Pg - Pg.transpose()).norm() < 1e-14);
  CHECK(Eigen::SelfAdjointEigenSolver<Matrix12d>(Pg).eigenvalues().minCoeff() > 0.0);
  // Joint [pose; global] covariance, then back to local: recovers P_LL.
  Matrix12x6d Jp;
  Matrix12d Jt;
  const TargetValue xg = local_to_global(pose, xl, &Jp, &Jt);
  Eigen::Matrix<double, 18, 18> J = Eigen::Matrix<double, 18, 18>::Zero();
  J.topLeftCorner<6, 6>().setIdentity();
  J.block<12, 6>(6, 0) = Jp;
  J.block<12, 12>(6, 6) = Jt;
  const Eigen::Matrix<double, 18, 18> Pjoint = J * P * J.transpose();
  const Matrix12d Pl = global_to_local_covariance(pose, xg, Pjoint);
  CHECK(rel_err(Pl, P.bottomRightCorner<12, 12>()) < 1e-12);
}

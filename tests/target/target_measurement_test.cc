#include <catch2/catch.hpp>

#include "common/math/quat.h"
#include "common/target/target_conversion.h"
#include "common/target/target_measurement.h"
#include "common/target/target_model.h"
#include "target_test_util.h"

using namespace vimot;
using namespace vimot::target;
using vimot::target::test::central_diff;
using vimot::target::test::rel_err;

namespace {

CameraExtrinsics sample_camera() {
  CameraExtrinsics cam;
  cam.R_ItoC = exp_so3(Eigen::Vector3d(0.1, -0.2, 1.4));
  cam.p_IinC = Eigen::Vector3d(0.05, -0.02, 0.01);
  return cam;
}

// A global target placed in front of the camera of the sample IMU pose.
TargetValue target_in_front(const PoseValue& pose, const CameraExtrinsics& cam) {
  TargetValue xl = test::sample_target();
  // p_TinC = [0.2, -0.1, 4] → p_TinI.
  xl.p_TinR = cam.R_ItoC.transpose() * (Eigen::Vector3d(0.2, -0.1, 4.0) - cam.p_IinC);
  return local_to_global(pose, xl);
}

}  // namespace

TEST_CASE("target point Jacobians equal central finite differences", "[target]") {
  const CameraExtrinsics cam = sample_camera();
  const PoseValue pose = imu_pose(test::sample_imu());
  const TargetValue xg = target_in_front(pose, cam);
  const TargetValue xl = global_to_local(pose, xg);
  const Eigen::Vector3d p_FinT(0.4, -0.3, 0.5);
  for (TargetRepresentation rep : {TargetRepresentation::kGlobal, TargetRepresentation::kLocal}) {
    INFO(to_string(rep));
    const PoseValue tp = rep == TargetRepresentation::kGlobal ? xg.pose() : xl.pose();
    const TargetPointPrediction m = predict_target_point(rep, pose, tp, p_FinT, cam);
    REQUIRE(m.valid);
    CHECK((m.z - m.p_FinC.head<2>() / m.p_FinC.z()).norm() < 1e-15);
    auto z_of = [&](const PoseValue& ip, const PoseValue& t, const Eigen::Vector3d& f) -> Eigen::VectorXd {
      return predict_target_point(rep, ip, t, f, cam).z;
    };
    const Eigen::MatrixXd Ni = central_diff(6, [&](const Eigen::VectorXd& d) {
      return z_of(boxplus(pose, Vector6d(d)), tp, p_FinT);
    });
    const Eigen::MatrixXd Nt = central_diff(6, [&](const Eigen::VectorXd& d) {
      return z_of(pose, boxplus(tp, Vector6d(d)), p_FinT);
    });
    const Eigen::MatrixXd Nf = central_diff(3, [&](const Eigen::VectorXd& d) {
      return z_of(pose, tp, p_FinT + Eigen::Vector3d(d));
    });
    CHECK(rel_err(m.H_imu_pose, Ni) < 1e-8);
    CHECK(rel_err(m.H_target_pose, Nt) < 1e-8);
    CHECK(rel_err(m.H_point, Nf) < 1e-8);
    if (rep == TargetRepresentation::kLocal) CHECK(m.H_imu_pose.isZero(0.0));
  }
}

TEST_CASE("global and local target measurements predict the same point", "[target]") {
  const CameraExtrinsics cam = sample_camera();
  const PoseValue pose = imu_pose(test::sample_imu());
  const TargetValue xg = target_in_front(pose, cam);
  const TargetValue xl = global_to_local(pose, xg);
  const Eigen::Vector3d p_FinT(-0.2, 0.3, 0.1);
  const auto mg = predict_target_point(TargetRepresentation::kGlobal, pose, xg.pose(), p_FinT, cam);
  const auto ml = predict_target_point(TargetRepresentation::kLocal, pose, xl.pose(), p_FinT, cam);
  CHECK((mg.p_FinC - ml.p_FinC).norm() < 1e-12);
  CHECK((mg.p_FinC - target_point_in_camera(TargetRepresentation::kGlobal, pose, xg.pose(), p_FinT, cam)).norm() <
        1e-12);
  // Chain rule: H_local ∘ ∂local/∂(pose, global) = [H_imu, H_target] of the global model.
  Matrix12x6d Jp;
  Matrix12d Jt;
  global_to_local(pose, xg, &Jp, &Jt);
  const Eigen::Matrix<double, 2, 6> Hi = ml.H_target_pose * Jp.topRows<6>();
  const Eigen::Matrix<double, 2, 6> Ht = ml.H_target_pose * Jt.topLeftCorner<6, 6>();
  CHECK(rel_err(Hi, mg.H_imu_pose) < 1e-10);
  CHECK(rel_err(Ht, mg.H_target_pose) < 1e-10);
  CHECK(rel_err(ml.H_point, mg.H_point) < 1e-10);
}

TEST_CASE("a point behind the camera is flagged invalid", "[target]") {
  const CameraExtrinsics cam;
  PoseValue tp;
  tp.p = Eigen::Vector3d(0.0, 0.0, -2.0);
  const auto m = predict_target_point(TargetRepresentation::kLocal, PoseValue{}, tp, Eigen::Vector3d::Zero(), cam);
  CHECK_FALSE(m.valid);
}

TEST_CASE("a re-linearised point's Jacobians do not see the gauge its carried covariance holds", "[target]") {
  const CameraExtrinsics cam = sample_camera();
  const estimator::ImuValue imu = test::sample_imu();
  const PoseValue pose = imu_pose(imu);
  const TargetValue xg = target_in_front(pose, cam);
  const Eigen::Vector3d p_lin(0.4, -0.3, 0.5);  // the first triangulation
  const Eigen::Vector3d p_new = p_lin + Eigen::Vector3d(0.03, -0.02, 0.04);
  const Eigen::Matrix<double, 3, 9> J = point_relinearization(p_lin, p_new);
  CHECK(J.middleCols<3>(3).isZero(0.0));  // only the point's error changes, by the rotation error
  CHECK(J.rightCols<3>().isIdentity(0.0));
  for (TargetRepresentation rep : {TargetRepresentation::kGlobal, TargetRepresentation::kLocal}) {
    INFO(to_string(rep));
    const TargetValue x = rep == TargetRepresentation::kGlobal ? xg : global_to_local(pose, xg);
    // The target gauge (rotation α, shift t; target_model.h): target-pose rows,
    // and the point's rows [p×]α − t at the point it was linearised at.
    const JointNullspace N = joint_unobservable_directions(rep, imu, x);
    Eigen::Matrix<double, 9, 6> gauge_lin;
    gauge_lin.topRows<6>() = N.block<6, 6>(15, 0);
    gauge_lin.block<3, 3>(6, 0) = skew(p_lin);
    gauge_lin.block<3, 3>(6, 3) = -Eigen::Matrix3d::Identity();
    const TargetPointPrediction m = predict_target_point(rep, pose, x.pose(), p_new, cam);
    REQUIRE(m.valid);
    const auto seen = [&](const Eigen::Matrix<double, 3, 6>& point_rows) -> double {
      return (m.H_imu_pose * N.block<6, 6>(0, 0) + m.H_target_pose * gauge_lin.topRows<6>() + m.H_point * point_rows)
          .cwiseAbs()
          .maxCoeff();
    };
    const double carried = seen(J * gauge_lin);
    const double stale = seen(gauge_lin.bottomRows<3>());
    INFO("carried " << carried << ", stale " << stale);
    CHECK(carried < 1e-12 * m.H_target_pose.cwiseAbs().maxCoeff());
    CHECK(stale > 1e-3);  // Jacobians at p_new against the first estimate's gauge: the leak
  }
}

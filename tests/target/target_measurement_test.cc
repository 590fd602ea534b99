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

TEST_CASE("a re-linearised point's Jacobians do not see the directions its carried covariance holds", "[target]") {
  const CameraExtrinsics cam = sample_camera();
  const estimator::ImuValue imu = test::sample_imu();
  const PoseValue pose = imu_pose(imu);
  const TargetValue xg = target_in_front(pose, cam);
  const Eigen::Vector3d p_lin(0.4, -0.3, 0.5);  // the first triangulation
  const Eigen::Vector3d p_new = p_lin + Eigen::Vector3d(0.03, -0.02, 0.04);
  for (TargetRepresentation rep : {TargetRepresentation::kGlobal, TargetRepresentation::kLocal}) {
    INFO(to_string(rep));
    const bool global = rep == TargetRepresentation::kGlobal;
    const TargetValue x = global ? xg : global_to_local(pose, xg);
    const Eigen::Matrix3d R_ItoT =
        global ? Eigen::Matrix3d(x.pose().R() * pose.R().transpose()) : Eigen::Matrix3d(x.pose().R());
    const Eigen::MatrixXd J = point_relinearization(rep, R_ItoT, p_lin, p_new);
    REQUIRE(J.cols() == (global ? 15 : 9));
    CHECK(J.middleCols<3>(3).isZero(0.0));  // only the point's error changes, by rotation errors
    CHECK(J.rightCols<3>().isIdentity(0.0));
    // Unobservable directions (target_model.h; finite-difference tested there):
    // the target gauge (rotation α, shift t) and, global, the world yaw and
    // position, in J's order [target pose; IMU pose (global); point], with the
    // point's rows [p×]α − t (world: 0) at the point it was linearised at.
    const JointNullspace N = joint_unobservable_directions(rep, imu, x);
    Eigen::MatrixXd directions = Eigen::MatrixXd::Zero(J.cols(), 10);
    directions.topRows<6>() = N.middleRows<6>(15);
    if (global) directions.middleRows<6>(6) = N.topRows<6>();
    directions.bottomRows<3>().leftCols<3>() = skew(p_lin);
    directions.bottomRows<3>().middleCols<3>(3) = -Eigen::Matrix3d::Identity();
    const TargetPointPrediction m = predict_target_point(rep, pose, x.pose(), p_new, cam);
    REQUIRE(m.valid);
    Eigen::MatrixXd H(2, J.cols());
    if (global) {
      H << m.H_target_pose, m.H_imu_pose, m.H_point;
    } else {
      H << m.H_target_pose, m.H_point;
    }
    const auto seen = [&](const Eigen::Matrix<double, 3, 10>& point_rows) -> double {
      Eigen::MatrixXd D = directions;
      D.bottomRows<3>() = point_rows;
      return (H * D).cwiseAbs().maxCoeff();
    };
    const double carried = seen(J * directions);
    const double stale = seen(directions.bottomRows<3>());
    INFO("carried " << carried << ", stale " << stale);
    CHECK(carried < 1e-12 * H.cwiseAbs().maxCoeff());
    CHECK(stale > 1e-3);  // Jacobians at p_new against the first estimate's directions: the leak
    if (global) {
      // Carried with T's own rotation error alone (the local map), the world
      // yaw would get point rows: the robot's yaw would leak.
      Eigen::MatrixXd J_T = J;
      J_T.middleCols<3>(6).setZero();
      CHECK(seen(J_T * directions) > 1e-3);
    }
  }
}

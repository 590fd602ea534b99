#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <functional>
#include <memory>
#include <random>

#include "common/estimator/linear_algebra.h"
#include "common/estimator/measurement_model.h"
#include "common/estimator/state.h"
#include "common/estimator/state_helper.h"
#include "common/estimator/triangulation.h"
#include "common/estimator/updater_msckf.h"
#include "common/estimator/updater_slam.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::estimator;

namespace {

CameraInfo test_camera(int i) {
  CameraInfo c;
  c.R_ItoC = exp_so3(Eigen::Vector3d(0.02, -1.55, 0.01 + 0.01 * i));
  c.p_IinC = Eigen::Vector3d(-0.02 + 0.11 * i, 0.06, 0.01);
  c.sigma_normalized = 1.0 / 450.0;
  return c;
}

ClonePose test_pose(int k) {
  ClonePose p;
  // Camera (IMU -x roughly) looks towards +x of G; poses move along y.
  p.R_GtoI = exp_so3(Eigen::Vector3d(0.05 * k, -0.02, 0.03 * k - 0.1)) * exp_so3(Eigen::Vector3d(0, 0, 0.0));
  p.p_IinG = Eigen::Vector3d(0.1 * k, 0.3 * k, 0.05 * k);
  return p;
}

// Central difference of f around 0 (f: R^n -> R^2).
template <int N>
Eigen::Matrix<double, 2, N> numeric(const std::function<Eigen::Vector2d(const Eigen::Matrix<double, N, 1>&)>& f) {
  Eigen::Matrix<double, 2, N> J;
  const double eps = 1e-6;
  for (int i = 0; i < N; ++i) {
    Eigen::Matrix<double, N, 1> d = Eigen::Matrix<double, N, 1>::Zero();
    d(i) = eps;
    J.col(i) = (f(d) - f(-d)) / (2.0 * eps);
  }
  return J;
}

State make_state(const std::vector<ClonePose>& poses, bool use_fej) {
  StateOptions so;
  so.use_fej = use_fej;
  so.max_clones = 30;
  State st(so);
  for (size_t k = 0; k < poses.size(); ++k) {
    ImuValue v;
    v.q_GtoI = rot_to_quat(poses[k].R_GtoI);
    v.p_IinG = poses[k].p_IinG;
    StateHelper::reset_imu(st, v, Eigen::Matrix<double, 15, 15>::Identity() * 1e-4);
    StateHelper::augment_clone(st, static_cast<int64_t>(k) * 100000);
  }
  return st;
}

}  // namespace

TEST_CASE("Projection Jacobians w.r.t. clone pose and global point", "[measurement]") {
  const CameraInfo cam = test_camera(0);
  const ClonePose pose = test_pose(1);
  const Eigen::Vector3d p_FinG = pose.p_IinG + pose.R_GtoI.transpose() *
                                                   (cam.R_ItoC.transpose() * (Eigen::Vector3d(0.3, -0.2, 4.0) - cam.p_IinC));
  Eigen::Matrix<double, 2, 6> H_pose;
  Eigen::Matrix<double, 2, 3> H_f;
  const Eigen::Vector2d z = global_point_measurement(pose.R_GtoI, pose.p_IinG, p_FinG, cam, &H_pose, &H_f);
  CHECK((z - Eigen::Vector2d(0.3 / 4.0, -0.2 / 4.0)).norm() < 1e-12);
  const auto num_pose = numeric<6>([&](const Eigen::Matrix<double, 6, 1>& d) {
    return global_point_measurement(exp_so3(-d.head<3>()) * pose.R_GtoI, pose.p_IinG + d.tail<3>(), p_FinG, cam,
                                    nullptr, nullptr);
  });
  const auto num_f = numeric<3>([&](const Eigen::Vector3d& d) {
    return global_point_measurement(pose.R_GtoI, pose.p_IinG, p_FinG + d, cam, nullptr, nullptr);
  });
  CHECK((H_pose - num_pose).cwiseAbs().maxCoeff() < 1e-8);
  CHECK((H_f - num_f).cwiseAbs().maxCoeff() < 1e-8);
}

TEST_CASE("Anchored inverse-depth Jacobians w.r.t. lambda and anchor pose", "[measurement]") {
  const CameraInfo cam = test_camera(1);
  const ClonePose anchor = test_pose(2);
  const Eigen::Vector3d lambda(0.1, -0.05, 0.25);
  Eigen::Matrix3d J_l;
  Eigen::Matrix<double, 3, 6> J_a;
  const Eigen::Vector3d p = anchored_to_global(lambda, anchor.R_GtoI, anchor.p_IinG, cam, &J_l, &J_a);
  CHECK((global_to_anchored(p, anchor.R_GtoI, anchor.p_IinG, cam) - lambda).norm() < 1e-12);
  const double eps = 1e-6;
  for (int i = 0; i < 3; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d(i) = eps;
    const Eigen::Vector3d num = (anchored_to_global(lambda + d, anchor.R_GtoI, anchor.p_IinG, cam, nullptr, nullptr) -
                                 anchored_to_global(lambda - d, anchor.R_GtoI, anchor.p_IinG, cam, nullptr, nullptr)) /
                                (2 * eps);
    CHECK((J_l.col(i) - num).norm() < 1e-6);
  }
  for (int i = 0; i < 6; ++i) {
    Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
    d(i) = eps;
    auto f = [&](const Eigen::Matrix<double, 6, 1>& e) {
      return anchored_to_global(lambda, exp_so3(-e.head<3>()) * anchor.R_GtoI, anchor.p_IinG + e.tail<3>(), cam,
                                nullptr, nullptr);
    };
    CHECK((J_a.col(i) - (f(d) - f(-d)) / (2 * eps)).norm() < 1e-6);
  }
}

TEST_CASE("Anchor change: value and finite-difference Jacobian", "[measurement][slam]") {
  const CameraInfo cam_a = test_camera(0), cam_b = test_camera(1);
  const ClonePose A = test_pose(1), B = test_pose(4);
  const Eigen::Vector3d lambda(0.1, -0.05, 0.2);
  // global_to_anchored's own Jacobians.
  {
    const Eigen::Vector3d p = anchored_to_global(lambda, A.R_GtoI, A.p_IinG, cam_a, nullptr, nullptr);
    Eigen::Matrix3d G_f;
    Eigen::Matrix<double, 3, 6> G_b;
    global_to_anchored(p, B.R_GtoI, B.p_IinG, cam_b, &G_f, &G_b);
    const double eps = 1e-6;
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(i) = eps;
      const Eigen::Vector3d num = (global_to_anchored(p + d, B.R_GtoI, B.p_IinG, cam_b) -
                                   global_to_anchored(p - d, B.R_GtoI, B.p_IinG, cam_b)) /
                                  (2 * eps);
      CHECK((G_f.col(i) - num).norm() < 1e-7);
    }
  }
  Eigen::Matrix<double, 3, 15> J;
  const Eigen::Vector3d lb = change_anchor(lambda, A.R_GtoI, A.p_IinG, cam_a, B.R_GtoI, B.p_IinG, cam_b, &J);
  // Same point.
  CHECK((anchored_to_global(lb, B.R_GtoI, B.p_IinG, cam_b, nullptr, nullptr) -
         anchored_to_global(lambda, A.R_GtoI, A.p_IinG, cam_a, nullptr, nullptr))
            .norm() < 1e-12);
  // Error order [λ̃_A, δθ_A, δp_A, δθ_B, δp_B] with the left error of the poses.
  auto f = [&](const Eigen::Matrix<double, 15, 1>& e) {
    return change_anchor(lambda + e.head<3>(), exp_so3(-e.segment<3>(3)) * A.R_GtoI, A.p_IinG + e.segment<3>(6),
                         cam_a, exp_so3(-e.segment<3>(9)) * B.R_GtoI, B.p_IinG + e.segment<3>(12), cam_b, nullptr);
  };
  const double eps = 1e-6;
  for (int i = 0; i < 15; ++i) {
    Eigen::Matrix<double, 15, 1> d = Eigen::Matrix<double, 15, 1>::Zero();
    d(i) = eps;
    const Eigen::Vector3d num = (f(d) - f(-d)) / (2 * eps);
    INFO("column " << i);
    CHECK((J.col(i) - num).norm() < 1e-6 * std::max(1.0, num.norm()));
  }
  // Moving both anchors together (a global translation) leaves λ_B unchanged.
  CHECK((J.middleCols<3>(6) + J.middleCols<3>(12)).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("Re-anchoring keeps the landmark's global position and covariance", "[measurement][slam]") {
  const std::vector<CameraInfo> cams = {test_camera(0), test_camera(1)};
  const std::vector<ClonePose> poses = {test_pose(0), test_pose(1), test_pose(2), test_pose(3)};
  for (bool use_fej : {false, true}) {
    State st = make_state(poses, use_fej);
    std::mt19937 rng(3);
    std::normal_distribution<double> n01;
    auto lm = std::make_shared<Landmark>(7, LandmarkRepresentation::kAnchoredInverseDepth);
    const ClonePose& a = poses[0];
    const Eigen::Vector3d p_FinG =
        a.p_IinG + a.R_GtoI.transpose() * (cams[1].R_ItoC.transpose() * (Eigen::Vector3d(0.4, 0.2, 5.0) - cams[1].p_IinC));
    lm->anchor_utime = 0;
    lm->anchor_camera = 1;
    lm->set_value(global_to_anchored(p_FinG, a.R_GtoI, a.p_IinG, cams[1]));
    lm->set_fej(lm->value() + Eigen::Vector3d(0.001, -0.002, 0.003));
    StateHelper::add_variable(st, lm, Eigen::Matrix3d::Identity() * 1e-4);
    StateHelper::register_slam_feature(st, lm);
    const int N = st.cov_size();
    Eigen::MatrixXd M(N, N);
    for (int i = 0; i < N; ++i) {
      for (int j = 0; j < N; ++j) M(i, j) = n01(rng);
    }
    // Correlate everything with one EKF update over all variables.
    REQUIRE(StateHelper::ekf_update(st, st.variables(), M.topRows(6), Eigen::VectorXd::Zero(6),
                                    Eigen::MatrixXd::Identity(6, 6) * 1e-3));
    const auto A = st.clone_at(0);
    const auto B = st.clones().rbegin()->second;
    const Eigen::MatrixXd P_before = st.cov();
    // Global point and its Jacobian w.r.t. [λ, A] before the change.
    Eigen::Matrix3d F_l;
    Eigen::Matrix<double, 3, 6> F_a;
    const Eigen::Vector3d p_before = anchored_to_global(lm->value(), A->Rot(), A->pos(), cams[1], &F_l, &F_a);
    const Eigen::Vector3d p_fej_before = anchored_to_global(lm->fej(), A->Rot_fej(), A->pos_fej(), cams[1], nullptr, nullptr);
    Eigen::MatrixXd T_before = Eigen::MatrixXd::Zero(3, N);
    T_before.middleCols(lm->id(), 3) = F_l;
    T_before.middleCols(A->id(), 6) = F_a;
    const Eigen::MatrixXd C_before = T_before * P_before;  // cov(p_FinG, x)

    UpdaterSlam slam(SlamOptions{}, TriangulationOptions{}, cams);
    REQUIRE(slam.change_anchors(st, 0) == 1);
    CHECK(lm->anchor_utime == st.clones().rbegin()->first);
    CHECK(lm->anchor_camera == 1);
    Eigen::Matrix3d G_l;
    Eigen::Matrix<double, 3, 6> G_b;
    const Eigen::Vector3d p_after = anchored_to_global(lm->value(), B->Rot(), B->pos(), cams[1], &G_l, &G_b);
    CHECK((p_after - p_before).norm() < 1e-12);
    CHECK((anchored_to_global(lm->fej(), B->Rot_fej(), B->pos_fej(), cams[1], nullptr, nullptr) - p_fej_before)
              .norm() < 1e-12);
    const Eigen::MatrixXd& P_after = st.cov();
    // Only the landmark's rows and columns change.
    Eigen::MatrixXd D = P_after - P_before;
    D.middleRows(lm->id(), 3).setZero();
    D.middleCols(lm->id(), 3).setZero();
    CHECK(D.cwiseAbs().maxCoeff() == 0.0);
    CHECK((P_after - P_after.transpose()).cwiseAbs().maxCoeff() < 1e-18);
    CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(P_after).eigenvalues().minCoeff() > -1e-15);
    if (!use_fej) {
      // Linearised at the estimate, the global point's covariance and its
      // correlations with the rest of the state are unchanged.
      Eigen::MatrixXd T_after = Eigen::MatrixXd::Zero(3, N);
      T_after.middleCols(lm->id(), 3) = G_l;
      T_after.middleCols(B->id(), 6) = G_b;
      const Eigen::MatrixXd C_after = T_after * P_after;
      const double scale = C_before.cwiseAbs().maxCoeff();
      // cov(p_FinG, every other variable) (the landmark's columns are a new variable).
      Eigen::MatrixXd dC = C_after - C_before;
      dC.middleCols(lm->id(), 3).setZero();
      CHECK(dC.cwiseAbs().maxCoeff() < 1e-9 * scale);
      CHECK((C_after * T_after.transpose() - C_before * T_before.transpose()).cwiseAbs().maxCoeff() < 1e-9 * scale);
    }
  }
}

TEST_CASE("SLAM landmark measurement Jacobians (global and anchored)", "[measurement][slam]") {
  const std::vector<CameraInfo> cams = {test_camera(0), test_camera(1)};
  const std::vector<ClonePose> poses = {test_pose(0), test_pose(1), test_pose(2)};
  for (auto rep : {LandmarkRepresentation::kGlobalXyz, LandmarkRepresentation::kAnchoredInverseDepth}) {
    State st = make_state(poses, /*use_fej=*/false);
    auto lm = std::make_shared<Landmark>(7, rep);
    const ClonePose& a = poses[1];
    const Eigen::Vector3d p_FinG =
        a.p_IinG + a.R_GtoI.transpose() * (cams[0].R_ItoC.transpose() * (Eigen::Vector3d(0.4, 0.2, 5.0) - cams[0].p_IinC));
    if (rep == LandmarkRepresentation::kGlobalXyz) {
      lm->set_value(p_FinG);
    } else {
      lm->anchor_utime = 100000;
      lm->anchor_camera = 0;
      lm->set_value(global_to_anchored(p_FinG, a.R_GtoI, a.p_IinG, cams[0]));
    }
    lm->set_fej(lm->value());
    StateHelper::add_variable(st, lm, Eigen::Matrix3d::Identity() * 0.01);
    StateHelper::register_slam_feature(st, lm);
    // Observed from every clone (the anchor one included) and both cameras.
    for (const auto& kv : st.clones()) {
      for (int c = 0; c < 2; ++c) {
        auto clone = kv.second;
        LandmarkMeasurement m;
        REQUIRE(landmark_measurement(st, *lm, *clone, c, cams, &m));
        auto eval = [&]() {
          LandmarkMeasurement mm;
          REQUIRE(landmark_measurement(st, *lm, *clone, c, cams, &mm));
          return mm.z_hat;
        };
        auto fd = [&](const TypePtr& var, int n) {
          Eigen::MatrixXd J(2, n);
          const Eigen::VectorXd x0 = var->value();
          for (int i = 0; i < n; ++i) {
            Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
            d(i) = 1e-6;
            var->update(d);
            const Eigen::Vector2d zp = eval();
            var->set_value(x0);
            var->update(-d);
            const Eigen::Vector2d zm = eval();
            var->set_value(x0);
            J.col(i) = (zp - zm) / 2e-6;
          }
          return J;
        };
        // Total derivative w.r.t. the observing clone (it may be the anchor).
        Eigen::Matrix<double, 2, 6> H_clone_total = m.H_clone;
        if (m.anchor && m.anchor == clone) H_clone_total += m.H_anchor;
        CHECK((fd(clone, 6) - H_clone_total).cwiseAbs().maxCoeff() < 1e-6);
        CHECK((fd(lm, 3) - m.H_landmark).cwiseAbs().maxCoeff() < 1e-6);
        if (m.anchor && m.anchor != clone) {
          CHECK((fd(m.anchor, 6) - m.H_anchor).cwiseAbs().maxCoeff() < 1e-6);
        }
      }
    }
  }
}

TEST_CASE("Left-nullspace projection annihilates H_f and keeps the residual consistent", "[measurement]") {
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  const int m = 14, nx = 12;
  Eigen::MatrixXd H_f(m, 3), H_x(m, nx);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < 3; ++j) H_f(i, j) = n01(rng);
    for (int j = 0; j < nx; ++j) H_x(i, j) = n01(rng);
  }
  Eigen::VectorXd x(nx), f(3);
  for (int j = 0; j < nx; ++j) x(j) = n01(rng);
  for (int j = 0; j < 3; ++j) f(j) = n01(rng);
  Eigen::VectorXd r = H_x * x + H_f * f;  // noise-free system
  const Eigen::MatrixXd H_f0 = H_f, H_x0 = H_x;
  Eigen::MatrixXd Hf = H_f;
  Eigen::MatrixXd Hx = H_x;
  Eigen::VectorXd rr = r;
  nullspace_project_inplace(Hf, Hx, rr);
  REQUIRE(Hx.rows() == m - 3);
  REQUIRE(rr.size() == m - 3);
  // The applied transform is orthogonal: recover Q2ᵀ from applying the same
  // rotations to the identity.
  Eigen::MatrixXd Hf2 = H_f0;
  Eigen::MatrixXd I = Eigen::MatrixXd::Identity(m, m);
  Eigen::VectorXd dummy = Eigen::VectorXd::Zero(m);
  givens_triangularize_inplace(Hf2, I, dummy);
  const Eigen::MatrixXd Q2t = I.bottomRows(m - 3);
  CHECK((Q2t * H_f0).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((Q2t * Q2t.transpose() - Eigen::MatrixXd::Identity(m - 3, m - 3)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((Q2t * H_x0 - Hx).cwiseAbs().maxCoeff() < 1e-12);
  // The feature drops out: r' = H_x' x exactly.
  CHECK((rr - Hx * x).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("Measurement compression keeps the information", "[measurement]") {
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  const int m = 40, n = 9;
  Eigen::MatrixXd H(m, n);
  Eigen::VectorXd r(m);
  for (int i = 0; i < m; ++i) {
    r(i) = n01(rng);
    for (int j = 0; j < n; ++j) H(i, j) = n01(rng);
  }
  Eigen::MatrixXd Hc = H;
  Eigen::VectorXd rc = r;
  measurement_compress_inplace(Hc, rc);
  CHECK(Hc.rows() == n);
  CHECK((Hc.transpose() * Hc - H.transpose() * H).cwiseAbs().maxCoeff() < 1e-10);
  CHECK((Hc.transpose() * rc - H.transpose() * r).cwiseAbs().maxCoeff() < 1e-10);

  // Stacked in pieces of 7, 3 and 30 rows: the same information.
  const std::vector<Eigen::MatrixXd> Hs = {H.topRows(7), H.middleRows(7, 3), H.bottomRows(30)};
  const std::vector<Eigen::VectorXd> rs = {r.head(7), r.segment(7, 3), r.tail(30)};
  Eigen::MatrixXd Hs_c;
  Eigen::VectorXd rs_c;
  stack_and_compress(Hs, rs, n, &Hs_c, &rs_c);
  CHECK(Hs_c.rows() == n);
  CHECK((Hs_c.transpose() * Hs_c - H.transpose() * H).cwiseAbs().maxCoeff() < 1e-10);
  CHECK((Hs_c.transpose() * rs_c - H.transpose() * r).cwiseAbs().maxCoeff() < 1e-10);
}

TEST_CASE("Triangulation recovers a point from stereo tracks", "[triangulation]") {
  const std::vector<CameraInfo> cams = {test_camera(0), test_camera(1)};
  ClonePoses poses;
  for (int k = 0; k < 5; ++k) poses[k * 100000] = test_pose(k);
  const ClonePose& a = poses.begin()->second;
  const Eigen::Vector3d p_true =
      a.p_IinG + a.R_GtoI.transpose() * (cams[0].R_ItoC.transpose() * (Eigen::Vector3d(0.5, -0.3, 6.0) - cams[0].p_IinC));
  for (double sigma : {0.0, 1.0 / 450.0}) {
    std::mt19937 rng(11);
    std::normal_distribution<double> noise(0.0, 1.0);
    Feature f;
    f.feature_id = 1;
    for (const auto& kv : poses) {
      for (int c = 0; c < 2; ++c) {
        const Eigen::Vector3d pc = point_in_camera(kv.second.R_GtoI, kv.second.p_IinG, p_true, cams[c]);
        f.obs[c].push_back(FeatureObs{kv.first, project(pc) + sigma * Eigen::Vector2d(noise(rng), noise(rng))});
      }
    }
    FeatureTriangulator tri(TriangulationOptions{}, cams);
    REQUIRE(tri.triangulate(f, poses));
    INFO("sigma " << sigma << " est " << f.p_FinG.transpose() << " true " << p_true.transpose());
    // 1 px at 6 m depth with ~1 m baseline: a few cm to ~0.1 m.
    CHECK((f.p_FinG - p_true).norm() < (sigma == 0.0 ? 1e-9 : 0.25));
    CHECK(f.anchor_utime == 0);
  }
  // One observation cannot be triangulated.
  Feature single;
  single.obs[0].push_back(FeatureObs{0, Eigen::Vector2d(0.1, 0.1)});
  FeatureTriangulator tri(TriangulationOptions{}, cams);
  CHECK_FALSE(tri.triangulate(single, poses));
}

TEST_CASE("MSCKF feature system: H_x and H_f are the residual Jacobians", "[measurement][msckf]") {
  const std::vector<CameraInfo> cams = {test_camera(0), test_camera(1)};
  const std::vector<ClonePose> poses = {test_pose(0), test_pose(1), test_pose(2), test_pose(3)};
  State st = make_state(poses, /*use_fej=*/false);
  const ClonePose& a = poses[0];
  Feature f;
  f.feature_id = 3;
  f.p_FinG = a.p_IinG + a.R_GtoI.transpose() * (cams[0].R_ItoC.transpose() * (Eigen::Vector3d(0.2, 0.1, 5.0) - cams[0].p_IinC));
  for (const auto& kv : st.clones()) {
    for (int c = 0; c < 2; ++c) {
      f.obs[c].push_back(FeatureObs{kv.first, project(point_in_camera(kv.second->Rot(), kv.second->pos(), f.p_FinG,
                                                                       cams[c])) + Eigen::Vector2d(1e-3, -2e-3)});
    }
  }
  UpdaterMsckf up(MsckfOptions{}, TriangulationOptions{}, cams);
  ColumnLayout layout;
  for (const auto& kv : st.clones()) layout.col(kv.second);
  Eigen::MatrixXd H_x, H_f;
  Eigen::VectorXd r0;
  REQUIRE(up.feature_system(st, f, layout, &H_x, &H_f, &r0));
  // r(x ⊞ δ) ≈ r(x) − H δ.
  for (const auto& var : layout.order()) {
    const int c0 = layout.col(var);
    const Eigen::VectorXd x0 = var->value();
    for (int i = 0; i < 6; ++i) {
      Eigen::VectorXd d = Eigen::VectorXd::Zero(6);
      d(i) = 1e-6;
      Eigen::MatrixXd a1, a2;
      Eigen::VectorXd rp, rm;
      var->update(d);
      up.feature_system(st, f, layout, &a1, &a2, &rp);
      var->set_value(x0);
      var->update(-d);
      up.feature_system(st, f, layout, &a1, &a2, &rm);
      var->set_value(x0);
      CHECK((-(rp - rm) / 2e-6 - H_x.col(c0 + i)).cwiseAbs().maxCoeff() < 1e-4);
    }
  }
  const Eigen::Vector3d pf0 = f.p_FinG;
  for (int i = 0; i < 3; ++i) {
    Eigen::MatrixXd a1, a2;
    Eigen::VectorXd rp, rm;
    f.p_FinG = pf0 + 1e-6 * Eigen::Vector3d::Unit(i);
    up.feature_system(st, f, layout, &a1, &a2, &rp);
    f.p_FinG = pf0 - 1e-6 * Eigen::Vector3d::Unit(i);
    up.feature_system(st, f, layout, &a1, &a2, &rm);
    f.p_FinG = pf0;
    CHECK((-(rp - rm) / 2e-6 - H_f.col(i)).cwiseAbs().maxCoeff() < 1e-4);
  }
}

TEST_CASE("MSCKF update defers the tracks above max_features_per_update", "[msckf]") {
  const std::vector<CameraInfo> cams = {test_camera(0), test_camera(1)};
  const std::vector<ClonePose> poses = {test_pose(0), test_pose(1), test_pose(2), test_pose(3)};
  State st = make_state(poses, /*use_fej=*/false);
  const ClonePose& a = poses[0];
  // Three exact tracks over 4, 3 and 2 clone times (stereo).
  std::vector<std::shared_ptr<Feature>> feats;
  for (int k = 0; k < 3; ++k) {
    auto f = std::make_shared<Feature>();
    f->feature_id = 10 + k;
    const Eigen::Vector3d p = a.p_IinG + a.R_GtoI.transpose() *
                                             (cams[0].R_ItoC.transpose() *
                                              (Eigen::Vector3d(0.2 - 0.3 * k, 0.1 * k, 5.0 + k) - cams[0].p_IinC));
    int n = 0;
    for (const auto& kv : st.clones()) {
      if (n++ >= 4 - k) break;
      for (int c = 0; c < 2; ++c) {
        f->obs[c].push_back(FeatureObs{kv.first, project(point_in_camera(kv.second->Rot(), kv.second->pos(), p,
                                                                           cams[c]))});
      }
    }
    feats.push_back(f);
  }
  MsckfOptions opt;
  opt.max_features_per_update = 1;
  UpdaterMsckf up(opt, TriangulationOptions{}, cams);
  UpdateStats stats;
  std::vector<std::shared_ptr<Feature>> deferred;
  up.update(st, {feats[2], feats[0], feats[1]}, &stats, &deferred);
  CHECK(stats.msckf_candidates == 3);
  CHECK(stats.msckf_dropped_over_max == 2);
  CHECK(stats.msckf_used == 1);  // the longest track
  REQUIRE(deferred.size() == 2);
  CHECK(deferred[0]->feature_id == 11);
  CHECK(deferred[1]->feature_id == 12);
}

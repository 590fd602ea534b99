#include <catch2/catch.hpp>

#include <Eigen/Dense>
#include <random>

#include "common/estimator/chi_square.h"
#include "common/estimator/state.h"
#include "common/estimator/state_helper.h"
#include "common/math/quat.h"

using namespace vimot;
using namespace vimot::estimator;

namespace {

Eigen::MatrixXd random_spd(int n, std::mt19937& rng) {
  std::normal_distribution<double> n01;
  Eigen::MatrixXd A(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) A(i, j) = n01(rng);
  }
  return 0.05 * (A * A.transpose() / n + 0.5 * Eigen::MatrixXd::Identity(n, n));
}

Eigen::MatrixXd random_matrix(int r, int c, std::mt19937& rng) {
  std::normal_distribution<double> n01;
  Eigen::MatrixXd A(r, c);
  for (int i = 0; i < r; ++i) {
    for (int j = 0; j < c; ++j) A(i, j) = n01(rng);
  }
  return A;
}

// A state [IMU(15) | pose(6) | pose(6) | vec3 | vec3] whose covariance is P.
struct TestState {
  State st{StateOptions{}};
  std::vector<TypePtr> vars;  // in covariance order
};

void build(TestState* ts, const Eigen::MatrixXd& P) {
  ImuValue x;
  x.q_GtoI = quat_normalize(Eigen::Vector4d(0.1, 0.2, -0.1, 1.0));
  x.p_IinG = Eigen::Vector3d(1, 2, 3);
  StateHelper::reset_imu(ts->st, x, P.topLeftCorner<15, 15>());
  ts->vars.push_back(ts->st.imu());
  std::vector<TypePtr> extra = {std::make_shared<PoseJPL>(), std::make_shared<PoseJPL>(), std::make_shared<Vec>(3),
                                std::make_shared<Vec>(3)};
  int id = 15;
  for (auto& v : extra) {
    Eigen::VectorXd val = v->value();
    if (val.size() == 7) val << quat_normalize(Eigen::Vector4d(0.3, -0.1, 0.2, 1.0)), 0.5, -0.2, 1.0;
    else val << 1.0, -2.0, 4.0;
    v->set_value(val);
    v->set_fej(val);
    StateHelper::add_variable(ts->st, v, P.block(id, id, v->size(), v->size()), P.block(id, 0, v->size(), id));
    ts->vars.push_back(v);
    id += v->size();
  }
}

// Values of every variable after applying dx with each type's ⊞.
std::vector<Eigen::VectorXd> expected_values(const TestState& ts, const Eigen::VectorXd& dx) {
  std::vector<Eigen::VectorXd> out;
  for (const auto& v : ts.vars) {
    auto c = v->clone_type();
    c->update(dx.segment(v->id(), v->size()));
    out.push_back(c->value());
  }
  return out;
}

}  // namespace

TEST_CASE("Subset EKF update equals the dense EKF", "[state_helper]") {
  std::mt19937 rng(1);
  const int N = 15 + 6 + 6 + 3 + 3;
  const Eigen::MatrixXd P = random_spd(N, rng);
  TestState ts;
  build(&ts, P);
  REQUIRE((ts.st.cov() - P).cwiseAbs().maxCoeff() < 1e-15);
  // Measurement on the second pose and the first vector (and IMU velocity part).
  auto pose2 = ts.vars[2];
  auto vec1 = ts.vars[3];
  auto vpart = ts.st.imu()->v();
  const std::vector<TypePtr> order = {vec1, pose2, vpart};
  const int m = 5;
  const Eigen::MatrixXd H = random_matrix(m, 12, rng);
  const Eigen::VectorXd r = random_matrix(m, 1, rng);
  const Eigen::MatrixXd R = 0.1 * Eigen::MatrixXd::Identity(m, m);
  // Dense reference.
  Eigen::MatrixXd Hd = Eigen::MatrixXd::Zero(m, N);
  Hd.middleCols(vec1->id(), 3) = H.leftCols(3);
  Hd.middleCols(pose2->id(), 6) = H.middleCols(3, 6);
  Hd.middleCols(vpart->id(), 3) = H.rightCols(3);
  const Eigen::MatrixXd S = Hd * P * Hd.transpose() + R;
  const Eigen::MatrixXd K = P * Hd.transpose() * S.inverse();
  const Eigen::MatrixXd P_ref = P - K * S * K.transpose();
  const auto x_ref = expected_values(ts, K * r);
  REQUIRE(StateHelper::ekf_update(ts.st, order, H, r, R));
  CHECK((ts.st.cov() - P_ref).cwiseAbs().maxCoeff() < 1e-12);
  for (size_t i = 0; i < ts.vars.size(); ++i) CHECK((ts.vars[i]->value() - x_ref[i]).norm() < 1e-12);
}

TEST_CASE("Schmidt update: nuisance untouched, Joseph-form covariance", "[state_helper][schmidt]") {
  std::mt19937 rng(2);
  const int N = 33;
  const Eigen::MatrixXd P = random_spd(N, rng);
  TestState ts;
  build(&ts, P);
  // Nuisance: the IMU and the first pose ("robot"); active: the rest ("target").
  const std::vector<TypePtr> nuisance = {ts.vars[0], ts.vars[1]};
  const std::vector<TypePtr> order = {ts.vars[1], ts.vars[2], ts.vars[4]};
  const int m = 6;
  const Eigen::MatrixXd H = random_matrix(m, 15, rng);
  const Eigen::VectorXd r = random_matrix(m, 1, rng);
  const Eigen::MatrixXd R = 0.05 * Eigen::MatrixXd::Identity(m, m);
  Eigen::MatrixXd Hd = Eigen::MatrixXd::Zero(m, N);
  Hd.middleCols(ts.vars[1]->id(), 6) = H.leftCols(6);
  Hd.middleCols(ts.vars[2]->id(), 6) = H.middleCols(6, 6);
  Hd.middleCols(ts.vars[4]->id(), 3) = H.rightCols(3);
  // Independent derivation: K = [0; K_a] with K_a the optimal gain rows,
  // P⁺ = (I − K H) P (I − K H)ᵀ + K R Kᵀ (Joseph form, valid for any K).
  const int nn = 21;  // IMU + first pose are the first 21 rows
  const Eigen::MatrixXd S = Hd * P * Hd.transpose() + R;
  Eigen::MatrixXd K = P * Hd.transpose() * S.inverse();
  K.topRows(nn).setZero();
  const Eigen::MatrixXd IKH = Eigen::MatrixXd::Identity(N, N) - K * Hd;
  const Eigen::MatrixXd P_ref = IKH * P * IKH.transpose() + K * R * K.transpose();
  const auto x_ref = expected_values(ts, K * r);
  const auto imu_before = ts.vars[0]->value();
  const auto pose_before = ts.vars[1]->value();
  REQUIRE(StateHelper::schmidt_update(ts.st, order, H, r, R, nuisance));
  const Eigen::MatrixXd& Pn = ts.st.cov();
  CHECK((Pn.topLeftCorner(nn, nn) - P.topLeftCorner(nn, nn)).cwiseAbs().maxCoeff() == 0.0);
  CHECK(ts.vars[0]->value() == imu_before);
  CHECK(ts.vars[1]->value() == pose_before);
  CHECK((Pn - P_ref).cwiseAbs().maxCoeff() < 1e-12);
  for (size_t i = 0; i < ts.vars.size(); ++i) CHECK((ts.vars[i]->value() - x_ref[i]).norm() < 1e-12);
  // Conservative: never below the full EKF covariance.
  const Eigen::MatrixXd Kf = P * Hd.transpose() * S.inverse();
  const Eigen::MatrixXd P_ekf = P - Kf * S * Kf.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Pn - P_ekf);
  CHECK(es.eigenvalues().minCoeff() > -1e-12);
}

TEST_CASE("Schmidt update with zero cross-covariance is the EKF of the active block", "[state_helper][schmidt]") {
  std::mt19937 rng(4);
  const int N = 33, nn = 21, na = N - nn;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(N, N);
  P.topLeftCorner(nn, nn) = random_spd(nn, rng);
  P.bottomRightCorner(na, na) = random_spd(na, rng);
  TestState ts;
  build(&ts, P);
  const std::vector<TypePtr> nuisance = {ts.vars[0], ts.vars[1]};
  const int m = 4;
  const Eigen::VectorXd r = random_matrix(m, 1, rng);
  const Eigen::MatrixXd R = 0.05 * Eigen::MatrixXd::Identity(m, m);

  SECTION("measurement of active variables only: exactly the plain EKF on the active block") {
    const Eigen::MatrixXd Ha = random_matrix(m, 9, rng);  // pose 2, vec 2
    const Eigen::MatrixXd Paa = P.bottomRightCorner(na, na);
    Eigen::MatrixXd H_act = Eigen::MatrixXd::Zero(m, na);
    H_act.leftCols(6) = Ha.leftCols(6);          // pose 2 at active offset 0
    H_act.rightCols(3) = Ha.rightCols(3);        // vec 2 at active offset 9
    const Eigen::MatrixXd S = H_act * Paa * H_act.transpose() + R;
    const Eigen::MatrixXd K = Paa * H_act.transpose() * S.inverse();
    const Eigen::MatrixXd Paa_ref = Paa - K * S * K.transpose();
    Eigen::VectorXd dx = Eigen::VectorXd::Zero(N);
    dx.tail(na) = K * r;
    const auto x_ref = expected_values(ts, dx);
    REQUIRE(StateHelper::schmidt_update(ts.st, {ts.vars[2], ts.vars[4]}, Ha, r, R, nuisance));
    CHECK((ts.st.cov().bottomRightCorner(na, na) - Paa_ref).cwiseAbs().maxCoeff() < 1e-13);
    CHECK(ts.st.cov().topRightCorner(nn, na).cwiseAbs().maxCoeff() == 0.0);
    CHECK((ts.st.cov().topLeftCorner(nn, nn) - P.topLeftCorner(nn, nn)).cwiseAbs().maxCoeff() == 0.0);
    for (size_t i = 0; i < ts.vars.size(); ++i) CHECK((ts.vars[i]->value() - x_ref[i]).norm() < 1e-13);
  }

  SECTION("measurement also of nuisance variables: EKF of the active block with R + H_n P_nn H_nᵀ") {
    const Eigen::MatrixXd H = random_matrix(m, 12, rng);  // first pose (nuisance), second pose (active)
    const Eigen::MatrixXd Hn = H.leftCols(6);
    const Eigen::MatrixXd Ha = H.rightCols(6);
    const Eigen::MatrixXd Pnn = P.block(15, 15, 6, 6);
    const Eigen::MatrixXd Paa = P.bottomRightCorner(na, na);
    Eigen::MatrixXd H_act = Eigen::MatrixXd::Zero(m, na);
    H_act.leftCols(6) = Ha;
    const Eigen::MatrixXd R_eff = R + Hn * Pnn * Hn.transpose();
    const Eigen::MatrixXd S = H_act * Paa * H_act.transpose() + R_eff;
    const Eigen::MatrixXd K = Paa * H_act.transpose() * S.inverse();
    const Eigen::MatrixXd Paa_ref = Paa - K * S * K.transpose();
    // Cross-covariance created: P_an⁺ = −K_a H_n P_nn (rows of the first pose).
    const Eigen::MatrixXd Pan_ref = -K * Hn * Pnn;
    REQUIRE(StateHelper::schmidt_update(ts.st, {ts.vars[1], ts.vars[2]}, H, r, R, nuisance));
    CHECK((ts.st.cov().bottomRightCorner(na, na) - Paa_ref).cwiseAbs().maxCoeff() < 1e-13);
    CHECK((ts.st.cov().block(nn, 15, na, 6) - Pan_ref).cwiseAbs().maxCoeff() < 1e-13);
    CHECK((ts.st.cov().topLeftCorner(nn, nn) - P.topLeftCorner(nn, nn)).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("Clone, marginalize and add_variable keep the covariance blocks", "[state_helper]") {
  std::mt19937 rng(7);
  const Eigen::MatrixXd P = random_spd(33, rng);
  TestState ts;
  build(&ts, P);
  auto copy = StateHelper::clone(ts.st, ts.st.imu()->pose());
  REQUIRE(copy->id() == 33);
  const Eigen::MatrixXd& C = ts.st.cov();
  CHECK((C.block(33, 0, 6, 33) - P.block(0, 0, 6, 33)).cwiseAbs().maxCoeff() == 0.0);
  CHECK((C.block(33, 33, 6, 6) - P.block(0, 0, 6, 6)).cwiseAbs().maxCoeff() == 0.0);
  CHECK(copy->value() == ts.st.imu()->pose()->value());
  // Marginalise the first pose (rows 15..20): the rest shifts.
  StateHelper::marginalize(ts.st, ts.vars[1]);
  CHECK(ts.vars[1]->id() == -1);
  CHECK(ts.vars[2]->id() == 15);
  CHECK(copy->id() == 27);
  Eigen::MatrixXd ref(33, 33);
  std::vector<int> keep;
  for (int i = 0; i < 39; ++i) {
    if (i < 15 || i >= 21) keep.push_back(i);
  }
  Eigen::MatrixXd Pc(39, 39);
  Pc.topLeftCorner(33, 33) = P;
  Pc.block(33, 0, 6, 33) = P.block(0, 0, 6, 33);
  Pc.block(0, 33, 33, 6) = P.block(0, 0, 33, 6);
  Pc.block(33, 33, 6, 6) = P.block(0, 0, 6, 6);
  for (int i = 0; i < 33; ++i) {
    for (int j = 0; j < 33; ++j) ref(i, j) = Pc(keep[i], keep[j]);
  }
  CHECK((ts.st.cov() - ref).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("initialize_invertible and initialize match the augmented-system solution", "[state_helper]") {
  std::mt19937 rng(9);
  const Eigen::MatrixXd P = random_spd(33, rng);
  TestState ts;
  build(&ts, P);
  const std::vector<TypePtr> order = {ts.vars[1], ts.vars[2]};
  const double sigma = 0.1;

  SECTION("invertible: covariance of x_new = H_L⁻¹ (r − H_R x̃_R − n)") {
    const Eigen::MatrixXd H_R = random_matrix(3, 12, rng);
    const Eigen::MatrixXd H_L = random_matrix(3, 3, rng) + 3.0 * Eigen::MatrixXd::Identity(3, 3);
    const Eigen::VectorXd r = 0.01 * random_matrix(3, 1, rng);
    auto f = std::make_shared<Vec>(3);
    f->set_value(Eigen::Vector3d(1, 1, 1));
    const Eigen::MatrixXd R = sigma * sigma * Eigen::MatrixXd::Identity(3, 3);
    StateHelper::initialize_invertible(ts.st, f, order, H_R, H_L, r, R);
    // Reference: x̃_new = −H_L⁻¹ H_R x̃_R − H_L⁻¹ n  (linear map of x̃ and n).
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3, 33);
    A.middleCols(15, 12) = -H_L.inverse() * H_R;
    const Eigen::MatrixXd Pvv = A * P * A.transpose() + H_L.inverse() * R * H_L.inverse().transpose();
    const Eigen::MatrixXd Pvx = A * P;
    CHECK((ts.st.cov().block(33, 33, 3, 3) - Pvv).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((ts.st.cov().block(33, 0, 3, 33) - Pvx).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((f->value() - (Eigen::Vector3d(1, 1, 1) + H_L.inverse() * r)).norm() < 1e-12);
  }

  SECTION("non-invertible: QR split, then the remaining rows update the state") {
    const int m = 8;
    const Eigen::MatrixXd H_R = random_matrix(m, 12, rng);
    const Eigen::MatrixXd H_L = random_matrix(m, 3, rng);
    Eigen::VectorXd r = sigma * random_matrix(m, 1, rng);
    auto f = std::make_shared<Vec>(3);
    REQUIRE(StateHelper::initialize(ts.st, f, order, H_R, H_L, r, sigma, 1e6));
    REQUIRE(f->id() == 33);
    // Reference: with an (infinitely) uninformative prior on the new
    // variable, the joint information-form solution. Equivalently, the
    // marginal on the old variables equals the EKF with the left-nullspace
    // projected rows of [H_R | H_L].
    Eigen::MatrixXd Hx = Eigen::MatrixXd::Zero(m, 33);
    Hx.middleCols(15, 12) = H_R;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(H_L, Eigen::ComputeFullU);
    const Eigen::MatrixXd U2 = svd.matrixU().rightCols(m - 3);
    const Eigen::MatrixXd Hp = U2.transpose() * Hx;
    const Eigen::MatrixXd S = Hp * P * Hp.transpose() + sigma * sigma * Eigen::MatrixXd::Identity(m - 3, m - 3);
    const Eigen::MatrixXd K = P * Hp.transpose() * S.inverse();
    const Eigen::MatrixXd P_old_ref = P - K * S * K.transpose();
    CHECK((ts.st.cov().topLeftCorner(33, 33) - P_old_ref).cwiseAbs().maxCoeff() < 1e-10);
  }

  SECTION("chi² failure leaves the state unchanged") {
    const int m = 8;
    const Eigen::MatrixXd H_R = random_matrix(m, 12, rng);
    const Eigen::MatrixXd H_L = random_matrix(m, 3, rng);
    const Eigen::VectorXd r = 100.0 * random_matrix(m, 1, rng);  // far too large
    auto f = std::make_shared<Vec>(3);
    const Eigen::MatrixXd before = ts.st.cov();
    CHECK_FALSE(StateHelper::initialize(ts.st, f, order, H_R, H_L, r, sigma, 1.0));
    CHECK(f->id() == -1);
    CHECK(ts.st.cov() == before);
  }
}

TEST_CASE("Covariance propagation touches only the evolving blocks", "[state_helper]") {
  std::mt19937 rng(12);
  const Eigen::MatrixXd P = random_spd(33, rng);
  TestState ts;
  build(&ts, P);
  const Eigen::MatrixXd Phi = Eigen::MatrixXd::Identity(15, 15) + 0.1 * random_matrix(15, 15, rng);
  const Eigen::MatrixXd Q = random_spd(15, rng);
  StateHelper::propagate(ts.st, {ts.st.imu()}, Phi, Q);
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(33, 33);
  F.topLeftCorner(15, 15) = Phi;
  Eigen::MatrixXd Qf = Eigen::MatrixXd::Zero(33, 33);
  Qf.topLeftCorner(15, 15) = Q;
  const Eigen::MatrixXd ref = F * P * F.transpose() + Qf;
  CHECK((ts.st.cov() - ref).cwiseAbs().maxCoeff() < 1e-13);
}

TEST_CASE("transform_variable equals T P Tᵀ with T = I but for the variable's rows", "[state_helper]") {
  std::mt19937 rng(5);
  const int N = 33;
  const Eigen::MatrixXd P = random_spd(N, rng);
  TestState ts;
  build(&ts, P);
  // The last vector (id 30) becomes J [vec, pose1, pose2]: as an anchor change.
  const auto vec = ts.vars[4];
  const std::vector<TypePtr> order = {vec, ts.vars[1], ts.vars[2]};
  const Eigen::MatrixXd J = random_matrix(3, 15, rng);
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(N, N);
  T.middleRows(vec->id(), 3).setZero();
  T.block(vec->id(), vec->id(), 3, 3) = J.leftCols(3);
  T.block(vec->id(), ts.vars[1]->id(), 3, 6) = J.middleCols(3, 6);
  T.block(vec->id(), ts.vars[2]->id(), 3, 6) = J.rightCols(6);
  const Eigen::MatrixXd P_ref = T * P * T.transpose();
  const auto values = ts.vars[3]->value();
  StateHelper::transform_variable(ts.st, vec, order, J);
  CHECK((ts.st.cov() - P_ref).cwiseAbs().maxCoeff() < 1e-14);
  CHECK(ts.vars[3]->value() == values);
  CHECK_THROWS_AS(StateHelper::transform_variable(ts.st, vec, {ts.vars[1]}, J.middleCols(3, 6)),
                  std::invalid_argument);
  CHECK_THROWS_AS(StateHelper::transform_variable(ts.st, vec, order, J.leftCols(9)), std::invalid_argument);
}

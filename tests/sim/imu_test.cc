// Simulated IMU checked by dead reckoning: the noise-free measurements,
// integrated by an RK4 written here (independent of any estimator code)
// from the true initial state, must reproduce the true trajectory. The noise
// model is checked by its sample statistics against the configured densities.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "common/sim/simulator.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

struct NavState {
  Eigen::Matrix3d R_ItoG;
  Eigen::Vector3d p, v;
};
struct NavDerivative {
  Eigen::Matrix3d dR;
  Eigen::Vector3d dp, dv;
};

// Kinematics: Ṙ = R [ω]x, ṗ = v, v̇ = R f + g.
NavDerivative f(const NavState& x, const Eigen::Vector3d& w, const Eigen::Vector3d& acc, double gravity) {
  Eigen::Matrix3d W;
  W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return {x.R_ItoG * W, x.v, x.R_ItoG * acc + Eigen::Vector3d(0, 0, -gravity)};
}

NavState add(const NavState& x, const NavDerivative& d, double h) {
  return {x.R_ItoG + h * d.dR, x.p + h * d.dp, x.v + h * d.dv};
}

struct Samples {
  std::vector<ImuSample> imu;
  std::vector<GroundTruth> gt;
};

Samples collect(Simulator& sim) {
  Samples s;
  sim.run([&s](const SimEvent& e) {
    if (const auto* m = std::get_if<ImuSample>(&e)) s.imu.push_back(*m);
    if (const auto* g = std::get_if<GroundTruth>(&e)) s.gt.push_back(*g);
  });
  return s;
}

// Dead reckoning with RK4 over steps of two IMU periods: samples k, k+1,
// k+2 are the RK4 start, mid and end points, so no input is interpolated.
// Returns the largest position error against the ground truth.
double rk4_max_position_error(const Samples& s, const Eigen::Vector3d& bg, const Eigen::Vector3d& ba, double gravity) {
  const GroundTruth& g0 = s.gt.front();
  // JPL q_GtoI -> R_ItoG written out here: R_GtoI = (2qw²-1)I - 2qw[qv]x + 2qv qvᵀ.
  const Eigen::Vector3d qv = g0.q_GtoI.head<3>();
  const double qw = g0.q_GtoI(3);
  Eigen::Matrix3d Qx;
  Qx << 0, -qv.z(), qv.y(), qv.z(), 0, -qv.x(), -qv.y(), qv.x(), 0;
  const Eigen::Matrix3d R_GtoI = (2 * qw * qw - 1) * Eigen::Matrix3d::Identity() - 2 * qw * Qx + 2 * qv * qv.transpose();
  NavState x{R_GtoI.transpose(), g0.p_IinG, g0.v_IinG};
  double max_err = 0.0;
  for (std::size_t k = 0; k + 2 < s.imu.size(); k += 2) {
    const double h = (s.imu[k + 2].utime - s.imu[k].utime) * 1e-6;
    auto w = [&](std::size_t i) { return Eigen::Vector3d(s.imu[i].w_IinI - bg); };
    auto a = [&](std::size_t i) { return Eigen::Vector3d(s.imu[i].a_IinI - ba); };
    const NavDerivative k1 = f(x, w(k), a(k), gravity);
    const NavDerivative k2 = f(add(x, k1, h / 2), w(k + 1), a(k + 1), gravity);
    const NavDerivative k3 = f(add(x, k2, h / 2), w(k + 1), a(k + 1), gravity);
    const NavDerivative k4 = f(add(x, k3, h), w(k + 2), a(k + 2), gravity);
    x.R_ItoG += h / 6 * (k1.dR + 2 * k2.dR + 2 * k3.dR + k4.dR);
    x.p += h / 6 * (k1.dp + 2 * k2.dp + 2 * k3.dp + k4.dp);
    x.v += h / 6 * (k1.dv + 2 * k2.dv + 2 * k3.dv + k4.dv);
    REQUIRE(s.gt[k + 2].utime == s.imu[k + 2].utime);
    max_err = std::max(max_err, (x.p - s.gt[k + 2].p_IinG).norm());
  }
  return max_err;
}

}  // namespace

TEST_CASE("Noise-free IMU dead-reckoned with RK4 from the true state follows the true trajectory") {
  const Eigen::Vector3d bg(0.01, -0.02, 0.015), ba(0.1, -0.05, 0.2);
  for (const char* file : {"config/sim_paper.yaml", "config/sim_mono.yaml"}) {
    SECTION(file) {
      SimConfig c = test::load_config(file);
      c.imu.rate_hz = 400.0;
      c.imu.noise = false;
      c.imu.initial_gyro_bias = bg;
      c.imu.initial_accel_bias = ba;
      c.duration = 10.0;
      Simulator sim(c);
      const Samples s = collect(sim);
      REQUIRE(s.imu.size() == 4001);
      REQUIRE(s.gt.size() == 4001);
      // The initial state for start-from-truth is the first ground truth.
      CHECK((sim.initial_state().p_IinG - s.gt.front().p_IinG).norm() == 0.0);
      CHECK((sim.initial_state().bias_gyro - bg).norm() == 0.0);
      // Without noise the biases stay what was configured.
      CHECK((s.gt.back().bias_accel - ba).norm() == 0.0);
      const double err = rk4_max_position_error(s, bg, ba, c.imu.gravity);
      INFO("max position error " << err << " m over 10 s");
      CHECK(err < 1e-3);
      // The integration is not trivially satisfied: the IMU moves and turns.
      double travelled = 0.0;
      for (std::size_t k = 1; k < s.gt.size(); ++k) travelled += (s.gt[k].p_IinG - s.gt[k - 1].p_IinG).norm();
      CHECK(travelled > 2.0);
    }
  }
}

TEST_CASE("IMU measurements equal the true angular rate and specific force plus biases") {
  SimConfig c = test::paper_config();
  c.imu.noise = false;
  c.imu.initial_gyro_bias = Eigen::Vector3d(0.001, 0.002, 0.003);
  c.duration = 2.0;
  Simulator sim(c);
  const Samples s = collect(sim);
  for (std::size_t k = 0; k < s.imu.size(); k += 37) {
    const SplineState truth = sim.robot_state(sim.sim_time(s.imu[k].utime));
    CHECK((s.imu[k].w_IinI - truth.w_BinB - c.imu.initial_gyro_bias).norm() < 1e-12);
    // a_I = R_GtoI (a_G - g), g = [0, 0, -9.81]: at hover it reads +9.81 up.
    const Eigen::Vector3d f_I = truth.R_BtoG.transpose() * (truth.a_BinG + Eigen::Vector3d(0, 0, 9.81));
    CHECK((s.imu[k].a_IinI - f_I).norm() < 1e-12);
  }
}

TEST_CASE("IMU white noise and bias random walk have the configured strengths") {
  SimConfig c = test::paper_config();
  c.imu.rate_hz = 200.0;
  c.imu.gyroscope_noise_density = 2e-3;
  c.imu.accelerometer_noise_density = 3e-2;
  c.imu.gyroscope_random_walk = 4e-4;
  c.imu.accelerometer_random_walk = 5e-3;
  c.duration = 60.0;
  c.camera.rate_hz = 1.0;  // cameras are not looked at here
  Simulator sim(c);
  const Samples s = collect(sim);
  const double dt = 1.0 / c.imu.rate_hz;
  double sg = 0, sa = 0, sbg = 0, sba = 0;
  std::size_t n = 0;
  for (std::size_t k = 0; k + 1 < s.imu.size(); ++k) {
    const SplineState truth = sim.robot_state(sim.sim_time(s.imu[k].utime));
    const Eigen::Vector3d ng = s.imu[k].w_IinI - truth.w_BinB - s.gt[k].bias_gyro;
    const Eigen::Vector3d na =
        s.imu[k].a_IinI - truth.R_BtoG.transpose() * (truth.a_BinG + Eigen::Vector3d(0, 0, 9.81)) - s.gt[k].bias_accel;
    sg += ng.squaredNorm();
    sa += na.squaredNorm();
    sbg += (s.gt[k + 1].bias_gyro - s.gt[k].bias_gyro).squaredNorm();
    sba += (s.gt[k + 1].bias_accel - s.gt[k].bias_accel).squaredNorm();
    ++n;
  }
  // Sample std over 3n ≈ 36000 draws: within 2 % of σ (statistical error ≈ 0.4 %).
  const double m = 3.0 * static_cast<double>(n);
  CHECK(std::sqrt(sg / m) == Approx(c.imu.gyroscope_noise_density / std::sqrt(dt)).epsilon(0.02));
  CHECK(std::sqrt(sa / m) == Approx(c.imu.accelerometer_noise_density / std::sqrt(dt)).epsilon(0.02));
  CHECK(std::sqrt(sbg / m) == Approx(c.imu.gyroscope_random_walk * std::sqrt(dt)).epsilon(0.02));
  CHECK(std::sqrt(sba / m) == Approx(c.imu.accelerometer_random_walk * std::sqrt(dt)).epsilon(0.02));
}

#pragma once
// Synthetic camera / object motions for the scale estimator tests (test
// only; the simulator scenarios come later). Every motion is analytic; the
// tracker output is made from the truth as
//   pbar_OinC = R_GtoC (p_OinG - p_CinG) / s,  R_OtoC = R_GtoC R_OtoG.

#include <cmath>
#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "common/math/quat.h"
#include "common/object/scale_estimator.h"

namespace vimot::scale::testing {

struct Pose {
  Eigen::Matrix3d R_XtoG{Eigen::Matrix3d::Identity()};
  Eigen::Vector3d p_XinG{Eigen::Vector3d::Zero()};
};
using Motion = std::function<Pose(double t)>;

struct Noise {
  double sigma_pbar{0.0};        // tracker position, up-to-scale units
  double sigma_p_cam{0.0};       // VINS camera position, m
  double sigma_theta_cam{0.0};   // VINS camera attitude, rad
  double jitter_s{0.0};          // timestamp jitter, uniform in [-jitter, jitter]
  unsigned seed{1};
};

constexpr double kTwoPi = 6.283185307179586;
constexpr int64_t kT0 = 1'000'000'000;  // 1000 s: utimes far from 0
constexpr double kDt = 0.05;            // 20 Hz
// 198 motion samples of a 200-observation window span 198 * kDt: sinusoids
// at integer multiples of 1 / kPeriod are exactly orthogonal over any 198
// consecutive uniform samples (DFT orthogonality), so the finite sample
// covariance of independent camera / object motions is exactly zero.
constexpr double kPeriod = 198 * kDt;

inline double harmonic(double t, int j, double phase = 0.0) {
  return std::sin(kTwoPi * j * t / kPeriod + phase);
}

/// Camera: multi-harmonic translation (bins 2-5) and rotation.
inline Pose normal_camera(double t) {
  Pose p;
  p.p_XinG = Eigen::Vector3d(0.8 * harmonic(t, 2) + 0.3 * harmonic(t, 5, 0.4),
                             0.6 * harmonic(t, 3, 1.5707963), 0.3 * harmonic(t, 4, 1.0));
  // Camera z (optical axis) roughly along world +x.
  Eigen::Matrix3d R0;
  R0 << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // columns: camera x, y, z axes in G
  const Eigen::Vector3d th(0.2 * harmonic(t, 1), 0.15 * harmonic(t, 2, 0.7), 0.3 * harmonic(t, 3, 0.2));
  p.R_XtoG = R0 * exp_so3(th);
  return p;
}

/// Object: independent translation (bins 6-9) ~4 m in front, and rotation.
inline Pose normal_object(double t) {
  Pose p;
  p.p_XinG = Eigen::Vector3d(4.0 + 0.5 * harmonic(t, 6, 0.3),
                             1.0 + 0.7 * harmonic(t, 7, 1.1) + 0.2 * harmonic(t, 9, 1.5707963),
                             0.2 * harmonic(t, 8));
  p.R_XtoG = exp_so3(Eigen::Vector3d(0.3 * harmonic(t, 2), 0.1 * harmonic(t, 5), 0.05 * t));
  return p;
}

/// Observation from true poses and the true scale s (noise-free).
inline ScaleObservation make_observation(int64_t utime, const Pose& cam, const Pose& obj, double s) {
  const Eigen::Matrix3d R_GtoC = cam.R_XtoG.transpose();
  return ScaleObservation::from_rotations(utime, cam.R_XtoG, cam.p_XinG, R_GtoC * obj.R_XtoG,
                                          R_GtoC * (obj.p_XinG - cam.p_XinG) / s);
}

/// `count` observations at 20 Hz from index `first` (t = k * kDt).
inline std::vector<ScaleObservation> generate(const Motion& camera, const Motion& object, double s,
                                              int count, int first = 0,
                                              const Noise& noise = Noise()) {
  std::mt19937 rng(noise.seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto gauss3 = [&](double sigma) {
    return Eigen::Vector3d(sigma * n01(rng), sigma * n01(rng), sigma * n01(rng));
  };
  std::vector<ScaleObservation> out;
  for (int k = first; k < first + count; ++k) {
    const double t = k * kDt + noise.jitter_s * u(rng);
    const int64_t utime = kT0 + static_cast<int64_t>(std::llround(t * 1e6));
    Pose cam = camera(t);
    const Pose obj = object(t);
    ScaleObservation o = make_observation(utime, cam, obj, s);
    o.pbar_OinC += gauss3(noise.sigma_pbar);
    // VINS error: the estimator sees a perturbed camera pose, and the
    // tracker output is still relative to the true camera.
    if (noise.sigma_p_cam > 0.0 || noise.sigma_theta_cam > 0.0) {
      const Eigen::Matrix3d R_CtoG_est = cam.R_XtoG * exp_so3(gauss3(noise.sigma_theta_cam));
      o.q_GtoC = rot_to_quat(R_CtoG_est.transpose());
      o.p_CinG += gauss3(noise.sigma_p_cam);
    }
    out.push_back(o);
  }
  return out;
}

/// Feeds all observations, returns the last update() result.
inline ScaleResult run(ScaleEstimator& est, const std::vector<ScaleObservation>& obs) {
  ScaleResult r;
  for (const ScaleObservation& o : obs) {
    est.add(o);
    r = est.update();
  }
  return r;
}

}  // namespace vimot::scale::testing

#pragma once
// Cumulative cubic B-spline on SE(3) with exact analytic derivatives.
//
// Formulation (Lovegrove, Patron-Perez, Sibley, "Spline Fusion", BMVC 2013;
// the same form as OpenVINS's ov_core::BsplineSE3): with uniformly spaced
// control poses T_k = T_BtoG(t0 + k dt) and t in the segment [t_i, t_i+1),
// u = (t - t_i) / dt,
//
//   T(t) = T_{i-1} exp(B1(u) Ω_i) exp(B2(u) Ω_{i+1}) exp(B3(u) Ω_{i+2}),
//   Ω_k = log(T_{k-1}^-1 T_k)       (se(3) twists, [ω; v] ordering)
//
// with the cumulative cubic basis
//   B1 = (5 + 3u - 3u² + u³)/6,  B2 = (1 + 3u + 3u² - 2u³)/6,  B3 = u³/6.
// The spline is C² (so IMU signals are continuous) and approximates, not
// interpolates, the control poses. Samples of a constant-twist motion
// T0 exp(t ξ) are reproduced exactly since B1 + B2 + B3 = 1 + u.
//
// Derivatives: d/dt exp(b Ω^) = exp(b Ω^) Ω^ ḃ, so Ṫ and T̈ follow from the
// product rule on the three factors. From them
//   ω_BinB = vee(Rᵀ Ṙ),  α_BinB = vee(Rᵀ R̈)  (Ṙᵀ Ṙ is symmetric),
//   v_BinG = ṗ,          a_BinG = p̈.
// The spline is valid for t in [t_1, t_{n-2}] (four control poses needed).

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace vimot {
namespace sim {

/// One timed pose of a body frame B (the IMU I, or a target T) in G.
struct TimedPose {
  double t{0.0};                                        // seconds (spline time)
  Eigen::Matrix3d R_BtoG{Eigen::Matrix3d::Identity()};  // body-to-world rotation
  Eigen::Vector3d p_BinG{Eigen::Vector3d::Zero()};      // body origin in G (m)
};

/// Pose and exact derivatives of the spline at one time.
struct SplineState {
  double t{0.0};                                        // seconds (spline time)
  Eigen::Matrix3d R_BtoG{Eigen::Matrix3d::Identity()};  // body-to-world rotation
  Eigen::Vector3d p_BinG{Eigen::Vector3d::Zero()};      // m, in G
  Eigen::Vector3d v_BinG{Eigen::Vector3d::Zero()};      // m/s, in G
  Eigen::Vector3d a_BinG{Eigen::Vector3d::Zero()};      // m/s², in G (no gravity)
  Eigen::Vector3d w_BinB{Eigen::Vector3d::Zero()};      // rad/s, in the body frame
  Eigen::Vector3d alpha_BinB{Eigen::Vector3d::Zero()};  // rad/s², in the body frame
};

class BsplineSE3 {
 public:
  /// Control poses T_BtoG (4x4 homogeneous) at times t0 + k dt. Needs at
  /// least 4 poses and dt > 0; throws std::invalid_argument otherwise.
  BsplineSE3(double t0, double dt, std::vector<Eigen::Matrix4d> control_T_BtoG);

  /// OpenVINS-style fit of timed poses (strictly increasing times): the
  /// poses are resampled at uniform dt from the first time on (geodesic
  /// interpolation between the bounding poses: slerp rotation, linear
  /// position) and the samples are used as control poses. The result is
  /// valid from poses.front().t + dt on.
  static BsplineSE3 fit(const std::vector<TimedPose>& poses, double dt);

  /// Control poses f(t) sampled every dt so that the spline is valid on at
  /// least [t_begin, t_end]: t_1 = t_begin.
  static BsplineSE3 from_function(const std::function<Eigen::Matrix4d(double)>& T_BtoG_of_t, double t_begin,
                                  double t_end, double dt);

  /// First and last time at which evaluate() is defined.
  double start_time() const { return t0_ + dt_; }
  double end_time() const { return t0_ + dt_ * static_cast<double>(control_.size() - 2); }
  bool valid(double t) const;

  double dt() const { return dt_; }
  const std::vector<Eigen::Matrix4d>& control_poses() const { return control_; }

  /// Pose and derivatives at t; throws std::out_of_range outside
  /// [start_time(), end_time()] (1 ns tolerance).
  SplineState evaluate(double t) const;

  /// Pose only (cheaper): T_BtoG at t.
  Eigen::Matrix4d pose(double t) const;

 private:
  // Segment index i (control poses i-1 .. i+2) and local parameter u.
  void locate(double t, int* i, double* u) const;

  double t0_{0.0};
  double dt_{0.0};
  std::vector<Eigen::Matrix4d> control_;
  std::vector<Eigen::Matrix<double, 6, 1>> omega_;  // omega_[k] = log(T_k^-1 T_k+1)
};

/// SE(3) exponential of a twist [ω; v]: [exp(ω), Jl(ω) v; 0 1].
Eigen::Matrix4d exp_se3(const Eigen::Matrix<double, 6, 1>& xi);

/// SE(3) logarithm, inverse of exp_se3 for rotation angles below π.
Eigen::Matrix<double, 6, 1> log_se3(const Eigen::Matrix4d& T);

/// Inverse of a rigid transform.
Eigen::Matrix4d inverse_se3(const Eigen::Matrix4d& T);

/// 4x4 homogeneous transform from a rotation and a translation.
Eigen::Matrix4d make_se3(const Eigen::Matrix3d& R, const Eigen::Vector3d& p);

}  // namespace sim
}  // namespace vimot

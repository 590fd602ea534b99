#pragma once
// IMU propagation of the state mean (closed form) and covariance (Φ, Q_d).
//
// Model (OpenVINS / Trawny-Roumeliotis, JPL q_GtoI, g = [0 0 9.81]ᵀ):
//   ω_m = ω + bg + n_g,   a_m = R_GtoI (a_G + g) + ba + n_a,
//   ḃg = n_wg,            ḃa = n_wa.
// Between two samples (t_k, t_k+1), dt = t_k+1 − t_k, the bias-corrected
// readings are held at the mean of the two samples, ŵ = ω̄_m − b̂g,
// â = ā_m − b̂a, and the mean is integrated in closed form:
//   R_k+1 = Exp(−ŵ dt) R_k                      (R = R_GtoI)
//   v_k+1 = v_k + R_kᵀ Γ1 â − g dt,   Γ1 = ∫₀^dt Exp(ŵτ) dτ
//   p_k+1 = p_k + v_k dt + R_kᵀ Γ2 â − ½ g dt²,  Γ2 = ∫₀^dt (dt−τ) Exp(ŵτ) dτ
// The error-state transition (order [δθ δp δv δbg δba], R = Exp(−δθ) R̂) is
// the exact Jacobian of this step; with FEJ the rotation/velocity/position
// at t_k are the first estimates (x_lin), which keeps the unobservable
// directions (yaw, global position) of the linearised system:
//   Φ_θθ = R_k+1 R_k,linᵀ,            Φ_θbg = −Jr(ŵ dt) dt
//   Φ_vθ = −[(v_k+1 − v_k,lin + g dt)×] R_k,linᵀ
//   Φ_pθ = −[(p_k+1 − p_k,lin − v_k,lin dt + ½ g dt²)×] R_k,linᵀ
//   Φ_vbg = −R_k,linᵀ D1,  Φ_vba = −R_k,linᵀ Γ1,  Φ_pv = I dt,
//   Φ_pbg = −R_k,linᵀ D2,  Φ_pba = −R_k,linᵀ Γ2,
//   D1 = ∂(Γ1(ω) â)/∂ω = −∫₀^dt Exp(ŵτ) [â×] Jr(ŵτ) τ dτ,
//   D2 = ∂(Γ2(ω) â)/∂ω = −∫₀^dt (dt−τ) Exp(ŵτ) [â×] Jr(ŵτ) τ dτ
// (D1, D2 by 4-point Gauss–Legendre, exact to O((|ŵ|dt)⁸)).
// Noise: white noise of density σ held over dt has variance σ²/dt and enters
// like a bias error, so with G_g = Φ_{θpv,bg}, G_a = Φ_{θpv,ba}:
//   Q_d = G_g G_gᵀ σ_g²/dt + G_a G_aᵀ σ_a²/dt + diag(0, 0, 0, σ_wg² dt I, σ_wa² dt I).

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include "common/estimator/state.h"
#include "common/estimator/types.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace estimator {

class VioExtension;

using Matrix15d = Eigen::Matrix<double, 15, 15>;

/// Continuous-time IMU noise densities (defaults: ADIS16448 as in EuRoC).
struct ImuNoise {
  double sigma_w{1.6968e-04};   // gyro white noise, rad/s/√Hz
  double sigma_a{2.0e-3};       // accel white noise, m/s²/√Hz
  double sigma_wb{1.9393e-05};  // gyro bias random walk, rad/s²/√Hz
  double sigma_ab{3.0e-3};      // accel bias random walk, m/s³/√Hz
};

/// The motion across an IMU gap (no samples, e.g. a sensor driver's
/// restart) is unknown: the readings are taken as the linear interpolation
/// of the samples around the gap plus white noise of these densities (the
/// platform's unknown angular and linear acceleration over the gap), which
/// the covariance takes on. 0: a gap is propagated with the sensor noise only.
struct ImuGapNoise {
  double sigma_w{0.0};  // rad/s/√Hz
  double sigma_a{0.0};  // m/s²/√Hz
  bool enabled() const { return sigma_w > 0.0 || sigma_a > 0.0; }
};

struct PropagatorOptions {
  ImuNoise noise;
  double gravity_magnitude{9.81};  // m/s²
  double max_gap_s{0.05};          // sample spacing above this is reported as a gap
  /// With gap noise, a gap is integrated in steps of at most max_gap_s
  /// (interpolated readings), each with the sensor plus the gap noise.
  ImuGapNoise gap_noise;
  double buffer_s{5.0};            // IMU history kept behind the newest sample
};

enum class ImuFeedStatus {
  kAccepted,
  kAcceptedAfterGap,     // accepted; spacing to the previous sample > max_gap_s
  kRejectedNonFinite,
  kRejectedDuplicate,    // same utime as the previous sample
  kRejectedOutOfOrder,   // older than the previous sample
};
const char* to_string(ImuFeedStatus status);

struct ImuFeedCounts {
  int64_t accepted{0};
  int64_t gaps{0};
  int64_t non_finite{0};
  int64_t duplicate{0};
  int64_t out_of_order{0};
};

struct PropagationReport {
  bool ok{false};              // state moved to the requested time
  int steps{0};                // integration steps
  bool extrapolated{false};    // no IMU sample at/after the target time: last one held
  bool gap{false};             // a step longer than max_gap_s
  double max_step_s{0.0};
  std::string message;         // why not ok / what was unusual
};

class Propagator {
 public:
  explicit Propagator(const PropagatorOptions& options);

  const PropagatorOptions& options() const { return options_; }
  Eigen::Vector3d gravity() const { return Eigen::Vector3d(0.0, 0.0, options_.gravity_magnitude); }

  /// Buffers one sample; never throws on bad data, says what it did.
  ImuFeedStatus feed_imu(const ImuData& imu);
  const ImuFeedCounts& counts() const { return counts_; }
  /// utime of the newest buffered sample, -1 if none.
  int64_t latest_utime() const { return buffer_.empty() ? -1 : buffer_.back().utime; }
  const std::deque<ImuData>& buffer() const { return buffer_; }

  /// Propagates mean and covariance of the IMU from state.utime() to utime
  /// (> state.utime()); afterwards the IMU FEJ equals the new estimate.
  PropagationReport propagate(State& state, int64_t utime);

  /// As propagate(), but variables of `extension` (vio_extension.h) are
  /// propagated jointly with the IMU (its Φ, Q over [imu; extra]); with
  /// extension == nullptr exactly propagate().
  PropagationReport propagate(State& state, int64_t utime, VioExtension* extension);

  /// propagate() then clones the new IMU pose into the window at utime.
  PropagationReport propagate_and_clone(State& state, int64_t utime);

  /// Mean-only prediction of the IMU at utime (state unchanged), e.g. for
  /// high-rate output; returns false without IMU data.
  bool predict_imu(const State& state, int64_t utime, ImuValue* out) const;

  /// Samples covering [t0, t1]: linear interpolation at both ends, the last
  /// sample held if none reaches t1 (report->extrapolated).
  std::vector<ImuData> select_readings(int64_t t0, int64_t t1, PropagationReport* report) const;

  /// One step with constant readings over dt (see header). x is the current
  /// estimate, x_lin the linearisation point at t_k (FEJ, or x itself).
  static void predict_step(const ImuValue& x, const ImuValue& x_lin, const Eigen::Vector3d& w_m,
                           const Eigen::Vector3d& a_m, double dt, const Eigen::Vector3d& gravity,
                           const ImuNoise& noise, ImuValue* x_new, Matrix15d* Phi, Matrix15d* Qd);

  /// Closed-form integrals Γ1 = ∫₀^dt Exp(ωτ)dτ and Γ2 = ∫₀^dt (dt−τ)Exp(ωτ)dτ.
  static void gamma_integrals(const Eigen::Vector3d& w, double dt, Eigen::Matrix3d* G1, Eigen::Matrix3d* G2);

  /// Drops samples older than utime, keeping one before it for interpolation.
  void clean_older_than(int64_t utime);
  /// Drops every buffered sample (the counts stay).
  void clear() { buffer_.clear(); }
  /// Puts a sample older than every buffered one in front (a restored
  /// state's last reading, so a gap after it is interpolated from it); false
  /// if it is not older or not finite.
  bool prepend(const ImuData& imu);

  /// The IMU prediction over [t0, t1] without touching a state: the mean x1
  /// from x0, and (if Phi/Q are given) the interval's Φ = ∏Φ_i and Q
  /// (Q ← Φ_i Q Φ_iᵀ + Q_i) linearised at x0_lin. For extensions that
  /// propagate more variables jointly with the IMU (StateHelper::propagate
  /// with a larger Φ). False without IMU data.
  bool predict_interval(const ImuValue& x0, const ImuValue& x0_lin, int64_t t0, int64_t t1, ImuValue* x1,
                        Matrix15d* Phi, Matrix15d* Q, PropagationReport* report) const;

 private:
  PropagatorOptions options_;
  std::deque<ImuData> buffer_;
  ImuFeedCounts counts_;
};

}  // namespace estimator
}  // namespace vimot

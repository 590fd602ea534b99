#pragma once
// Online estimate of the target's process-noise density σ_t and a check of
// the target model's consistency (the `adaptive` target mode; derivation in
// docs/target_model.md, "Adaptive target noise").
//
// Covariance matching (Myers & Tapley) on the driven components j of the
// target's velocities (planar: v_x, v_y, w_z). Their transition is the
// identity and their discrete noise σ² dt (target_model.h), so for one frame
//   P⁻ = P⁺_prev + σ² dt,   E[Δx Δxᵀ] = P⁻ − P⁺   (Δx = x⁺ − x⁻, all updates)
// if σ is right, and each frame gives the unbiased sample
//   q̂_j = Δx_j² − (P⁻_jj − P⁺_jj) + σ_used² dt.
// Over a window of W frames, σ̂² = Σ q̂ / Σ dt (per component), clamped.
// Horizon h > 1 squares the corrections summed over h consecutive frames,
//   q̂_j = (Σ_h Δx_j)² − Σ_h (P⁻_jj − P⁺_jj) + Σ_h σ_used² dt,
// over every run of h frames in the window: still unbiased when σ is right
// (a right model's corrections K r are uncorrelated from frame to frame),
// but a sustained acceleration, which a white-noise model sees as
// corrections of one sign frame after frame, counts as the (Σ a dt)² it
// drives over h frames rather than as h samples of (a dt)²: the density
// the filter needs over its own memory, not the per-frame mean.
//
// Consistency: the normalised innovation squared of the target's measurement
// blocks (χ² before the gate, so rejected blocks count) per frame and over
// the window, NIS = Σχ² / Σdof (1 for a right model). A frame whose Σχ²
// exceeds nis_max · χ²_0.99(Σdof) violates the model: the window's evidence (gathered under a
// rejected σ) is dropped and σ² is inflated by min(NIS, max_step) — when the
// gate rejects the target's measurements no update carries the matching
// signal, so the innovations must — and the driven components' variance
// gets what the new σ would have added over the time the rejected one was
// used: a density √(σ_new² − σ_old²) over τ (inflation(), inflation_time():
// the filter's P of the target was computed with a σ now judged wrong, and
// TargetFilter propagates that noise through the target's motion, so its pose
// gets the share it integrated too). The model is judged consistent (tight
// coupling allowed) once `window` frames have passed without a violation and
// the windowed NIS is at most nis_max. A frame whose first blocks (the
// in-state points) already violate takes its steps before its update
// (inflate_before_update), so its measurements correct the target rather
// than being gated out while σ is bracketed frame by frame.
//
// Hold: the σ used is the largest windowed estimate of the last hold_s
// seconds. The matched σ̂ is the target's *mean* density; a manoeuvring
// target (stops, speed changes) exceeds it for seconds at a time, and a σ
// too small then corrupts the robot (the paper's Table I) while one too
// large only forgoes part of the gain. So the estimate follows the target's
// hardest recent manoeuvre up at once and forgets it only after hold_s.

#include <Eigen/Core>
#include <array>
#include <deque>

#include "common/estimator/checkpoint.h"

namespace vimot {
namespace target {

struct AdaptiveNoiseOptions {
  int window{40};           // frames of the matching and NIS windows
  double sigma_min{0.001};  // clamp of σ̂ (m/s²/√Hz, rad/s²/√Hz)
  double sigma_max{2.0};
  /// Bound of the windowed NIS, and factor on a frame's χ²_0.99(Σdof): the
  /// blocks of a frame share the target's pose error, so Σχ² is wider than
  /// χ²(Σdof) and the plain quantile would flag consistent frames.
  double nis_max{2.0};
  double max_step{4.0};     // largest σ² factor of one violating frame
  double hold_s{0.0};       // [s] σ = the largest windowed σ̂ of this long (0: the latest)
  int horizon{1};           // frames whose corrections are summed before squaring (<= window)
  /// Used by TargetFilter: when the model is first judged consistent and its
  /// σ then exceeds the σ the target was started under by more than one
  /// violation's largest step (σ² · max_step), start the target again from its
  /// features (its frame was made under a σ found too small;
  /// docs/target_model.md, "The restart").
  bool restart{false};
  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

class AdaptiveNoise {
 public:
  AdaptiveNoise(const AdaptiveNoiseOptions& options, double sigma0);

  /// χ² and dof of one target measurement block of the current frame.
  void add_innovation(double chi2, int dof);
  /// Ends a frame whose propagation used sigma() over dt seconds: x⁻, P⁻ of
  /// the driven components after that propagation, x⁺, P⁺ after every
  /// update of the frame (diagonals). Updates sigma() and consistent().
  void end_frame(const Eigen::VectorXd& x_minus, const Eigen::VectorXd& P_minus, const Eigen::VectorXd& x_plus,
                 const Eigen::VectorXd& P_plus, double dt);
  /// Ends a frame with no propagation to match (the target's first frame,
  /// or one inflated before its update: its P⁻ holds the inflation, not σ² dt),
  /// dt long (0 for the first).
  void end_frame_innovations_only(double dt = 0.0);
  /// Before a frame's update: if the χ² of its blocks so far (dof, the frame
  /// propagated over dt) violate the model, takes the violation's σ step now
  /// and returns true; inflation() is then the variance to add before the
  /// blocks are gated (their χ² computed again and passed in again), so the
  /// frame's measurements correct the target instead of being rejected. Once
  /// the frame violated it steps until χ² ≤ χ²_0.95(dof) (where the gate
  /// accepts the blocks). False when done or at sigma_max.
  bool inflate_before_update(double chi2, int dof, double dt);

  double sigma() const { return sigma_; }
  /// The latest windowed estimate (the mean density), before the hold.
  double matched_sigma() const { return matched_; }
  bool consistent() const { return consistent_; }
  double window_nis() const;
  int64_t violations() const { return violations_; }
  /// Variance to add to each driven component after the last frame,
  /// (σ_new² − σ_old²) τ (0 unless it violated the model), and τ.
  double inflation() const { return inflation_; }
  double inflation_time() const { return inflation_time_; }

  /// Its whole memory into a checkpoint (target_checkpoint.h), and back
  /// (false if the bytes are not one).
  void save(estimator::CheckpointWriter* out) const;
  bool load(estimator::CheckpointReader* in);

 private:
  static constexpr int kMaxComponents = 6;
  struct Frame {
    std::array<double, kMaxComponents> dx{};  // Δx_j of the frame's updates
    int components{0};     // driven components (0: no matching in this frame)
    double c_sum{0.0};     // Σ_j σ_used² dt − (P⁻_jj − P⁺_jj)
    double dt{0.0};
    double chi2{0.0};
    int dof{0};
  };
  void finish(Frame f);
  /// σ̂² of the window (false when it holds no complete horizon).
  bool window_density(double* q_density) const;
  bool violates(double chi2, int dof) const;
  /// The violation's bookkeeping and σ step (NIS of the violating blocks).
  void violate(double nis, double dt);

  AdaptiveNoiseOptions options_;
  double sigma_;
  double matched_;
  double time_{0.0};                               // Σ dt of the frames so far
  std::deque<std::pair<double, double>> recent_;   // (time_, windowed σ̂) of the last hold_s
  std::deque<Frame> window_;
  double frame_chi2_{0.0};
  int frame_dof_{0};
  int frames_since_violation_{0};
  bool consistent_{false};
  int64_t violations_{0};
  double inflation_{0.0};
  double inflation_time_{0.0};
  double frame_tau_{0.0};  // τ of the current frame's first violation (0: none yet)
};

}  // namespace target
}  // namespace vimot

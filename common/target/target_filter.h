#pragma once
// Joint robot + target filter (Eckenhoff et al., "Schmidt-EKF-based
// Visual-Inertial Moving Object Tracking", Sec. III–V) on top of the
// VioEstimator through its extension hooks (common/estimator/vio_extension.h).
//
// State added to the estimator's State (same covariance):
//   * TargetState x_T = [q_RtoT, p_TinR, v_TinT, w_TinT] (value 13, error 12,
//     R = G global or R = I local; the error convention of target_types.h),
//     propagated jointly with the IMU over every camera interval with
//     target::propagate_target + joint_transition (local: the target is
//     correlated with the IMU through Φ_TI and Q_TI);
//   * target pose clones [q_RtoT, p_TinR] at the IMU clone times, added with
//     the IMU clone and marginalised with it. A local clone is the target
//     pose relative to the IMU *at the clone time*, i.e. relative to its IMU
//     clone (the paper's local clones).
// Static-feature updates (MSCKF, SLAM) update the whole state, so the target
// is corrected through its correlations with the robot.
//
// Target update (after the static updates of a frame), MSCKF-style: a target
// point track is used when it is lost or is seen at the IMU clone about to
// leave the window; its observations at clone times are kept; the point
// p_FinT is triangulated in the target frame from the camera poses in T
// (IMU clone ∘ target clone); the stacked whitened system
//   r = H_x x̃ + H_f p̃_FinT + n   (H_x over target clones; global also IMU clones)
// is projected onto the left nullspace of H_f and gated by χ²
// (rᵀ(H P Hᵀ + I)⁻¹ r < chi2_multiplier · χ²_0.95(dof)). Modes:
//   kOff   no target update (the target is only predicted),
//   kEkf   StateHelper::ekf_update on everything (tightly coupled),
//   kSkf   StateHelper::schmidt_update with every non-target variable (IMU,
//          IMU clones, SLAM landmarks) as nuisance: robot estimate and P_RR
//          are never changed by a target update.
//   kAdaptive  σ_t estimated online from sigma_t on (AdaptiveNoise,
//          adaptive_noise.h: covariance matching on v, w, windowed NIS of
//          the target's measurement blocks); kEkf updates while the target
//          model is judged consistent, kSkf otherwise.
// Target points in the state (paper Eq. 2), SLAM-like: a target track
// still seen at the current frame with observations at >= point_init_clone_times
// target clones (longest first, up to max_target_points) is triangulated in
// T and added with StateHelper::initialize (χ² test on the rows left after
// the Givens split; under kSkf the same split with initialize_invertible and
// a Schmidt update of the remaining rows). Each frame the current
// observations of the in-state points update [target pose, (IMU pose,
// global), p_FinT] (per-point χ² gate, then one stacked update in the
// filter's mode). A point not updated for point_max_lost_frames frames is
// marginalised; when the cap is reached, points not seen at the current
// frame are marginalised (longest unseen first) to make room. The persistent
// points anchor the T origin across windows, which MSCKF-only target updates
// cannot (docs/target_model.md). Target points are target (active) variables
// under kSkf. The MSCKF-style update above stays for the other tracks.
// Initialisation (init_mode; docs/target_model.md, "Start from the target's
// features"):
//   kFeatures (default, no ground truth): once feature_init.frames
//     consecutive frames each have at least feature_init.min_points target
//     features seen by two cameras (triangulated in I from that stereo pair
//     alone: the target moves), the features seen in all of them give a
//     centroid per frame, placed in G with the robot's estimate then. T is
//     *defined* at the last frame: origin at the centroid, axes those of G
//     (R_GtoT = I: z up, as the planar model needs), v_TinT = the centroids'
//     least-squares slope, w = 0. T's pose relative to its points is a gauge,
//     so its start pose gets only the small init_sigmas.{theta,p} fixing it
//     relative to the robot; v gets the slope's noise plus the robot's
//     velocity error, w feature_init.sigma_w (init_sigmas.w on the axes the
//     planar model does not drive). The cross-covariance with the robot is
//     that of this start function's Jacobian (global: composed with
//     local_to_global's), as a delayed initialisation.
//   kGroundTruth (simulation, the paper's convention): from the ground truth
//     at the first frame with target observations (set_ground_truth() before
//     feed_camera), with the prior init_sigmas (uncorrelated with the robot).

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/estimator/feature_database.h"
#include "common/estimator/triangulation.h"
#include "common/estimator/vio_estimator.h"
#include "common/estimator/vio_extension.h"
#include "common/target/adaptive_noise.h"
#include "common/target/target_model.h"
#include "common/target/target_types.h"
#include "common/types/ground_truth.h"

namespace vimot {
namespace target {

/// Target state variable: value [q_RtoT (JPL); p_TinR; v_TinT; w_TinT] (13),
/// error [δθ δp δv δw] (12). pose() (rows 0..5), v(), w() are parts.
class TargetState : public estimator::Type {
 public:
  TargetState();
  void set_local_id(int new_id) override;
  void update(const Eigen::VectorXd& dx) override;
  void set_value(const Eigen::VectorXd& value) override;
  void set_fej(const Eigen::VectorXd& fej) override;
  void set_exact(const Eigen::VectorXd& value, const Eigen::VectorXd& fej) override;
  std::shared_ptr<estimator::Type> clone_type() const override;
  bool contains(const estimator::Type* other) const override;

  TargetValue get() const;
  TargetValue get_fej() const;
  std::shared_ptr<estimator::PoseJPL> pose() const { return pose_; }
  std::shared_ptr<estimator::Vec> v() const { return v_; }
  std::shared_ptr<estimator::Vec> w() const { return w_; }

 private:
  std::shared_ptr<estimator::PoseJPL> pose_;
  std::shared_ptr<estimator::Vec> v_;
  std::shared_ptr<estimator::Vec> w_;
};

enum class TargetUpdateMode { kOff, kEkf, kSkf, kAdaptive };
const char* to_string(TargetUpdateMode mode);

struct TargetInitSigmas {
  double theta{0.01};  // rad
  double p{0.01};      // m
  double v{0.05};      // m/s
  double w{0.01};      // rad/s
};

enum class TargetInitMode { kFeatures, kGroundTruth };
const char* to_string(TargetInitMode mode);

/// Start of the target from its own stereo features (TargetInitMode::kFeatures).
struct TargetFeatureInit {
  int frames{5};                    // consecutive frames the same features are triangulated in (>= 2)
  int min_points{10};               // stereo-triangulated target features in every one of them
  double max_point_distance{2.0};   // m from the points' median; farther ones are outliers
  double sigma_w{0.5};              // rad/s, prior of the zero start angular velocity
};

/// What the feature initialisation did (TargetFilter::feature_init_info).
struct TargetFeatureInitInfo {
  int64_t utime{0};
  std::vector<int64_t> feature_ids;  // the target features whose centroid is T's origin
  Eigen::Vector3d centroid_in_I{Eigen::Vector3d::Zero()};
  /// Covariance of the centroid from the stereo triangulation (pixel noise
  /// only): how far the origin is from the true centroid of those points.
  Eigen::Matrix3d centroid_cov{Eigen::Matrix3d::Zero()};
};

struct TargetFilterOptions {
  TargetUpdateMode mode{TargetUpdateMode::kSkf};
  TargetInitMode init_mode{TargetInitMode::kFeatures};
  TargetFeatureInit feature_init;
  TargetRepresentation representation{TargetRepresentation::kLocal};
  double sigma_t{0.05};   // target noise density (v: m/s²/√Hz, w: rad/s²/√Hz); kAdaptive: its start
  AdaptiveNoiseOptions adaptive;  // kAdaptive only
  bool planar{true};      // only v_x, v_y, w_z driven (paper Sec. IV)
  /// kGroundTruth: the start's prior. kFeatures: theta and p fix the gauge
  /// of the target frame (see above); v and w come from feature_init.
  TargetInitSigmas init_sigmas;
  /// The initialisation from the truth (simulation) draws its error from the
  /// init_sigmas prior with this seed, so the prior is honest; 0 = no error.
  uint64_t init_perturb_seed{0};
  double chi2_multiplier{1.0};
  int min_clone_times{2};
  /// With the estimator's FEJ: constrain the target rows of the joint
  /// transition so that it maps the directions that stay unobservable under
  /// the target's noise (target::noise_invariant_directions: planar, the
  /// target's yaw and vertical shift; world yaw and position) at one first
  /// estimate onto those at the next (docs/target_model.md). Off by default:
  /// FEJ alone measured as well (NEES in the band, same accuracy).
  bool observability_constraint{false};
  // Target points in the state (0 disables them: MSCKF-only target updates).
  int max_target_points{25};
  int point_init_clone_times{3};
  int point_max_lost_frames{10};
  /// With FEJ: an in-state point is linearised at its current estimate, its
  /// covariance carried along the target's gauge (point_relinearization);
  /// false keeps its first triangulation for good (docs/target_model.md).
  bool relinearize_points{true};
  estimator::TriangulationOptions triangulation;

  TargetNoise noise() const { return noise(sigma_t); }
  /// The noise model (planar or isotropic) at density sigma.
  TargetNoise noise(double sigma) const;
};

struct TargetUpdateStats {
  int64_t updates{0};              // frames with a target update applied
  int64_t tracks_used{0};
  int64_t rejected_short{0};
  int64_t rejected_triangulation{0};
  int64_t rejected_chi2{0};
  int64_t rows{0};
  int64_t obs_received{0};         // target observations handed to update()
  int64_t obs_used{0};             // observations in tracks that passed the gate
  // Whitened raw residuals (before the nullspace projection) of used tracks:
  // sum, sum of squares, count (diagnostics: mean should be ≈ 0).
  int64_t points_initialized{0};
  int64_t points_rejected_init{0};   // triangulation, rank or χ² at initialisation
  int64_t point_updates{0};          // point observations sets used in updates
  int64_t points_rejected_chi2{0};
  int64_t points_marginalized{0};
  // kAdaptive: frames ended, of them tightly coupled (EKF), model
  // violations, Σσ̂ over the frames (mean σ̂ = sum / frames), last σ̂.
  int64_t adaptive_frames{0};
  int64_t adaptive_coupled_frames{0};
  int64_t adaptive_violations{0};
  double adaptive_sigma_sum{0.0};
  double adaptive_sigma_last{0.0};
  int64_t target_restarts{0};  // kAdaptive with adaptive.restart: target started again
  double residual_sum{0.0};
  double residual_sq_sum{0.0};
  int64_t residual_count{0};
};

/// A target point p_FinT kept in the state.
struct TargetPoint {
  std::shared_ptr<estimator::Vec> var;
  int64_t last_updated_frame{0};
};

class TargetFilter : public estimator::VioExtension {
 public:
  /// Attaches itself to `estimator` (which must outlive it); detaches in the
  /// destructor.
  TargetFilter(estimator::VioEstimator& estimator, const TargetFilterOptions& options);
  ~TargetFilter() override;
  TargetFilter(const TargetFilter&) = delete;
  TargetFilter& operator=(const TargetFilter&) = delete;

  /// Ground truth for the initialisation (used if its utime is the frame's;
  /// ignored unless init_mode is kGroundTruth).
  void set_ground_truth(const GroundTruth& truth) { truth_ = truth; }
  /// The feature initialisation (init_mode kFeatures, once initialised).
  const std::optional<TargetFeatureInitInfo>& feature_init_info() const { return feature_init_info_; }

  const TargetFilterOptions& options() const { return options_; }
  bool initialized() const { return static_cast<bool>(target_); }
  /// How many times the target was started (0 before the first start). A
  /// change means a new target frame: a transform to it must be taken again.
  int32_t starts() const { return starts_; }
  /// kAdaptive: whether the model has been judged consistent at least once.
  bool model_verified() const { return model_verified_; }
  /// kAdaptive: the σ the target was last started under.
  double sigma_at_start() const { return sigma_at_start_; }
  /// The target variable (nullptr before initialisation).
  const std::shared_ptr<TargetState>& target() const { return target_; }
  const std::map<int64_t, std::shared_ptr<estimator::PoseJPL>>& clones() const { return clones_; }
  TargetValue value() const;
  /// Covariance (12×12) of the target error.
  Matrix12d covariance() const;
  /// Target position in the current IMU frame and its covariance (3×3)
  /// (local: p_TinI itself; global: R_GtoI (p_TinG − p_IinG), covariance by
  /// the Jacobian w.r.t. [δθ_I δp_I δp_T]).
  Eigen::Vector3d p_TinI(Eigen::Matrix3d* cov = nullptr) const;
  const TargetUpdateStats& stats() const { return stats_; }
  /// Target points in the state, by feature id.
  const std::map<int64_t, TargetPoint>& points() const { return points_; }
  /// The σ_t estimate and consistency check (kAdaptive only, else nullptr).
  const AdaptiveNoise* adaptive() const { return adaptive_ ? &*adaptive_ : nullptr; }
  /// The bookkeeping a checkpoint needs beside the state's variables
  /// (target_checkpoint.h): the frame count and the target feature tracks.
  int64_t frame_count() const { return frame_; }
  const estimator::FeatureDatabase& tracks() const { return tracks_; }
  /// Takes over a checkpoint's target (nullptr: not initialised), its
  /// clones and points (already in the estimator's state), tracks, frame
  /// count and σ_t estimate (kAdaptive); what lives within a frame is cleared.
  void restore(std::shared_ptr<TargetState> target, std::map<int64_t, std::shared_ptr<estimator::PoseJPL>> clones,
               std::map<int64_t, TargetPoint> points, estimator::FeatureDatabase tracks, int64_t frame,
               std::optional<AdaptiveNoise> adaptive, int32_t starts, bool model_verified, double sigma_at_start);
  /// Whether target updates now change the robot (kEkf, or kAdaptive judged consistent).
  bool tightly_coupled() const;

  // estimator::VioExtension
  bool propagate_jointly(const estimator::State& state, const estimator::ImuValue& x0, const estimator::ImuValue& x1,
                         const estimator::Matrix15d& Phi_II, const estimator::Matrix15d& Q_II, int64_t t0, int64_t t1,
                         std::vector<estimator::TypePtr>* order, Eigen::MatrixXd* Phi, Eigen::MatrixXd* Q) override;
  void commit_propagation(estimator::State& state) override;
  void on_clone_added(estimator::State& state, int64_t utime) override;
  void on_clone_marginalized(estimator::State& state, int64_t utime) override;
  void update(estimator::State& state, int64_t utime,
              const std::vector<FeatureObservation>& target_observations) override;
  void reset() override;

 private:
  bool initialize_from_truth(estimator::State& state, int64_t utime);
  // Target features seen by two cameras at utime, triangulated in I from that
  // frame alone, with their covariances, outliers removed; nullopt if fewer
  // than feature_init.min_points.
  struct StereoPoints {
    int64_t utime{0};
    estimator::ImuValue imu;  // the robot's estimate at utime
    std::map<int64_t, Eigen::Vector3d> p_FinI;
    std::map<int64_t, Eigen::Matrix3d> cov_I;
  };
  std::optional<StereoPoints> stereo_target_points(const estimator::State& state, int64_t utime,
                                                   const std::vector<FeatureObservation>& target_observations) const;
  bool initialize_from_features(estimator::State& state, int64_t utime,
                                const std::vector<FeatureObservation>& target_observations);
  // Adds the target (the representation's value) with covariance P_TT and
  // cross-covariance P_Tx with the current state (empty: none), and its
  // clone at utime if the IMU has one.
  void add_target(estimator::State& state, int64_t utime, const TargetValue& x, const Matrix12d& P_TT,
                  const Eigen::MatrixXd& P_Tx);
  void update_tracks(estimator::State& state, std::vector<std::shared_ptr<estimator::Feature>> tracks);
  void update_points(estimator::State& state, const std::vector<FeatureObservation>& obs);
  void initialize_points(estimator::State& state, int64_t utime);
  void marginalize_point(estimator::State& state, int64_t feature_id);
  // Removes the target, its clones and points from the state and forgets its
  // tracks; the features start begins again at the next frame.
  void restart_target(estimator::State& state);
  // IMU pose at each IMU+target clone time in T; `times` gets those times.
  estimator::ClonePoses poses_in_target(const estimator::State& state, std::set<int64_t>* times) const;
  // Every variable but the target, its clones and the target points.
  std::vector<estimator::TypePtr> nuisance_variables(const estimator::State& state) const;
  // Target clones (and IMU clones, global) at `times`, in clone order.
  estimator::ColumnLayout clone_layout(const estimator::State& state, const std::set<int64_t>& times) const;
  // Whitened system of one target track over those clones, r = H_x δx + H_f δp_FinT
  // (prediction at the estimates, Jacobians at the first estimates). False if an
  // observation names an unknown camera or lies behind one.
  bool track_system(const estimator::State& state, const estimator::Feature& f, const Eigen::Vector3d& p_FinT,
                    estimator::ColumnLayout& layout, Eigen::MatrixXd* H_x, Eigen::MatrixXd* H_f,
                    Eigen::VectorXd* r) const;
  // Driven components of the target's error state (planar: v_x, v_y, w_z).
  std::vector<int> driven_components() const;
  // kAdaptive: closes the frame's covariance matching, sets noise_ to σ̂ and
  // inflates the target's covariance after a model violation.
  void end_adaptive_frame(estimator::State& state);
  /// Adds the adaptive estimate's inflation() to the target (propagated
  /// through its motion) and takes its σ for the next propagation.
  void apply_inflation(estimator::State& state);
  // ekf_update (tightly_coupled()) or schmidt_update with nuisance_variables.
  bool apply_update(estimator::State& state, const std::vector<estimator::TypePtr>& order, const Eigen::MatrixXd& H,
                    const Eigen::VectorXd& r);

  estimator::VioEstimator& estimator_;
  TargetFilterOptions options_;
  TargetNoise noise_;
  std::shared_ptr<TargetState> target_;
  std::map<int64_t, std::shared_ptr<estimator::PoseJPL>> clones_;
  std::optional<TargetValue> pending_;
  estimator::FeatureDatabase tracks_;
  std::optional<GroundTruth> truth_;
  std::optional<TargetFeatureInitInfo> feature_init_info_;
  std::deque<StereoPoints> init_window_;  // consecutive frames towards the features start
  TargetUpdateStats stats_;
  std::map<int64_t, TargetPoint> points_;
  int64_t frame_{0};
  int32_t starts_{0};
  bool model_verified_{false};
  double sigma_at_start_{0.0};
  std::optional<AdaptiveNoise> adaptive_;
  // kAdaptive: driven components' values and covariance after this frame's
  // propagation, and its length (s).
  struct Predicted {
    Eigen::VectorXd x, P;
    double dt{0.0};
  };
  std::optional<Predicted> predicted_;
  // The driven components' values and variances now, with dt attached.
  Predicted driven_now(const estimator::State& state, double dt) const;
  double pending_dt_{0.0};
  bool inflated_this_frame_{false};  // adaptive: σ stepped before this frame's update
};

}  // namespace target
}  // namespace vimot

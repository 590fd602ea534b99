#include "common/object/object_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <ceres/ceres.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>

#include "common/math/quat.h"

namespace vimot {

namespace {

constexpr double kDegToRad = M_PI / 180.0;
// The initialisation starts from a two-view guess, far from the optimum
// compared with a tracked frame's PnP pose: it gets more iterations.
constexpr int kInitIterationFactor = 5;
// Floor of the pixel noise in the initialisation's hypothesis test, so that
// noise-free input gives a finite chi-square gap.
constexpr double kMinNoisePx = 0.01;

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Eigen::Vector3d homogeneous(const Eigen::Vector2d& normalized) { return {normalized.x(), normalized.y(), 1.0}; }

// Eq. 2's residual: feature l, a point in O, projected into camera j,
// minus its normalized observation. The pose is T_OtoC (R_OtoC as Eigen
// quaternion, pbar_OinC). Every view is a residual: a point fixed to its
// first (anchor) ray would keep that view's noise forever.
struct PointReprojection {
  explicit PointReprojection(const Eigen::Vector2d& observed) : observed_(observed) {}

  template <typename T>
  bool operator()(const T* q_j, const T* p_j, const T* point, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> q_OtoCj(q_j);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> pbar_OinCj(p_j);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> p_FinO(point);
    const Eigen::Matrix<T, 3, 1> p_FinCj = q_OtoCj * p_FinO + pbar_OinCj;
    residual[0] = p_FinCj.x() / p_FinCj.z() - T(observed_.x());
    residual[1] = p_FinCj.y() / p_FinCj.z() - T(observed_.y());
    return true;
  }

  Eigen::Vector2d observed_;
};

// Linear triangulation of X_a = d_a b_a with X_b = R X_a + t = d_b b_b
// (least squares in the two depths); returns X_a, or nothing if either depth
// is not positive.
std::optional<Eigen::Vector3d> triangulate(const Eigen::Vector3d& b_a, const Eigen::Vector3d& b_b,
                                           const Eigen::Matrix3d& R_atob, const Eigen::Vector3d& t_ainb) {
  Eigen::Matrix<double, 3, 2> A;
  A.col(0) = R_atob * b_a;
  A.col(1) = -b_b;
  const Eigen::Vector2d d = A.colPivHouseholderQr().solve(-t_ainb);
  if (!(d(0) > 0.0) || !(d(1) > 0.0) || !std::isfinite(d(0))) return std::nullopt;
  return Eigen::Vector3d(d(0) * b_a);
}

// Where the box centre (pixels) points: an affine map pixel -> normalized
// fitted to this frame's target features, so the library needs no camera
// model (distortion is smooth over a box). Falls back to the features'
// normalized centroid if the fit is degenerate.
Eigen::Vector3d centre_ray(const std::vector<FeatureObservation>& target, const Eigen::Vector2d& centre_px) {
  Eigen::MatrixXd A(target.size(), 3);
  Eigen::MatrixXd B(target.size(), 2);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < target.size(); ++i) {
    A.row(static_cast<Eigen::Index>(i)) << target[i].pixel.x(), target[i].pixel.y(), 1.0;
    B.row(static_cast<Eigen::Index>(i)) = target[i].normalized.transpose();
    centroid += target[i].normalized / static_cast<double>(target.size());
  }
  Eigen::Vector2d n = centroid;
  if (target.size() >= 3) {
    const Eigen::Matrix<double, 3, 2> M = A.colPivHouseholderQr().solve(B);
    const Eigen::Vector2d fit = (Eigen::RowVector3d(centre_px.x(), centre_px.y(), 1.0) * M).transpose();
    if (fit.allFinite()) n = fit;
  }
  return homogeneous(n).normalized();
}

// How far the points are from lying on one plane: the smallest over the
// middle principal standard deviation of their positions (0 planar, 1 as
// thick as wide).
template <typename Features>
double structure_thickness(const Features& features) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& [id, f] : features) mean += f.p_FinO;
  mean /= static_cast<double>(features.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& [id, f] : features) scatter += (f.p_FinO - mean) * (f.p_FinO - mean).transpose();
  // Ascending.
  const Eigen::Vector3d eigenvalues = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvalues();
  return eigenvalues(1) > 0.0 ? std::sqrt(std::max(eigenvalues(0), 0.0) / eigenvalues(1)) : 0.0;
}

}  // namespace

ObjectTrackerOptions object_tracker_options_from_config(const Config& config) {
  config.check_keys("", {"object_tracker", "channels"});
  ObjectTrackerOptions o;
  if (!config.has("object_tracker")) return o;
  config.check_keys("object_tracker",
                    {"window_size", "focal_length_px", "robust_loss", "robust_loss_px", "min_init_features",
                     "min_init_parallax_deg", "init_frames", "init_min_chi2_gap", "init_min_thickness",
                     "ransac_threshold_px", "reference_features", "min_track_features", "max_reprojection_rms_px",
                     "outlier_threshold_px", "min_feature_parallax_deg", "min_feature_observations", "max_iterations",
                     "keyframe_rotation_deg", "keyframe_baseline", "reassociation_px", "max_retired_poses"});
  const Config c = config.sub("object_tracker");
  o.window_size = c.get_or<int>("window_size", o.window_size);
  o.focal_length_px = c.get_or<double>("focal_length_px", o.focal_length_px);
  o.robust_loss = c.get_or<std::string>("robust_loss", o.robust_loss);
  o.robust_loss_px = c.get_or<double>("robust_loss_px", o.robust_loss_px);
  o.min_init_features = c.get_or<int>("min_init_features", o.min_init_features);
  o.min_init_parallax_deg = c.get_or<double>("min_init_parallax_deg", o.min_init_parallax_deg);
  o.init_frames = c.get_or<int>("init_frames", o.init_frames);
  o.init_min_chi2_gap = c.get_or<double>("init_min_chi2_gap", o.init_min_chi2_gap);
  o.init_min_thickness = c.get_or<double>("init_min_thickness", o.init_min_thickness);
  o.ransac_threshold_px = c.get_or<double>("ransac_threshold_px", o.ransac_threshold_px);
  o.reference_features = c.get_or<int>("reference_features", o.reference_features);
  o.min_track_features = c.get_or<int>("min_track_features", o.min_track_features);
  o.max_reprojection_rms_px = c.get_or<double>("max_reprojection_rms_px", o.max_reprojection_rms_px);
  o.outlier_threshold_px = c.get_or<double>("outlier_threshold_px", o.outlier_threshold_px);
  o.min_feature_parallax_deg = c.get_or<double>("min_feature_parallax_deg", o.min_feature_parallax_deg);
  o.min_feature_observations = c.get_or<int>("min_feature_observations", o.min_feature_observations);
  o.max_iterations = c.get_or<int>("max_iterations", o.max_iterations);
  o.keyframe_rotation_deg = c.get_or<double>("keyframe_rotation_deg", o.keyframe_rotation_deg);
  o.keyframe_baseline = c.get_or<double>("keyframe_baseline", o.keyframe_baseline);
  o.reassociation_px = c.get_or<double>("reassociation_px", o.reassociation_px);
  o.max_retired_poses = c.get_or<int>("max_retired_poses", o.max_retired_poses);
  auto require = [&c](bool ok, const std::string& key, const std::string& what) {
    if (!ok) c.fail(key, what + ", got " + c.get<std::string>(key));
  };
  require(o.window_size >= 3, "window_size", "must be >= 3");
  require(o.focal_length_px > 0.0, "focal_length_px", "must be > 0");
  require(o.robust_loss == "huber" || o.robust_loss == "cauchy", "robust_loss", "must be huber or cauchy");
  require(o.init_frames >= 2, "init_frames", "must be >= 2");
  require(o.reassociation_px >= 0.0, "reassociation_px", "must be >= 0");
  require(o.init_min_chi2_gap >= 0.0, "init_min_chi2_gap", "must be >= 0");
  require(o.init_min_thickness >= 0.0 && o.init_min_thickness <= 1.0, "init_min_thickness", "must be in [0, 1]");
  require(o.min_init_features >= 8, "min_init_features", "must be >= 8");
  require(o.reference_features >= 1, "reference_features", "must be >= 1");
  require(o.min_track_features >= 4, "min_track_features", "must be >= 4");
  require(o.min_feature_observations >= 2, "min_feature_observations", "must be >= 2");
  require(o.max_retired_poses >= 0, "max_retired_poses", "must be >= 0 (0: no limit)");
  return o;
}

ObjectTracker::ObjectTracker(ObjectTrackerOptions options) : options_(std::move(options)) {}

ObjectPoseEstimate ObjectTracker::process(const CameraFrame& frame, const std::optional<BoundingBox2d>& box) {
  ++counters_.frames;
  ObjectPoseEstimate invalid;
  invalid.utime = frame.utime;
  if (last_utime_ && frame.utime == *last_utime_) {
    ++counters_.rejected_duplicate_time;
    return invalid;
  }
  if (last_utime_ && frame.utime < *last_utime_) {
    ++counters_.rejected_time_backwards;
    return invalid;
  }
  last_utime_ = frame.utime;

  std::vector<FeatureObservation> target;
  for (const FeatureObservation& o : frame.observations) {
    if (o.camera_id != 0 || !o.is_target) continue;
    if (!o.pixel.allFinite() || !o.normalized.allFinite()) {
      ++counters_.dropped_non_finite_observations;
      continue;
    }
    target.push_back(o);
  }
  Observations obs;
  for (const FeatureObservation& o : target) obs[o.feature_id] = o.normalized;

  if (tracking_) return track(frame.utime, obs);
  if (target.empty()) {
    init_frames_.clear();
    return invalid;
  }
  Eigen::Vector2d centre_px;
  if (box && box->min_px.allFinite() && box->max_px.allFinite()) {
    centre_px = 0.5 * (box->min_px + box->max_px);
  } else {
    Eigen::Vector2d lo = target.front().pixel, hi = lo;
    for (const FeatureObservation& o : target) {
      lo = lo.cwiseMin(o.pixel);
      hi = hi.cwiseMax(o.pixel);
    }
    centre_px = 0.5 * (lo + hi);
  }
  return try_initialise(InitFrame{frame.utime, std::move(obs), centre_ray(target, centre_px)});
}

ObjectPoseEstimate ObjectTracker::try_initialise(InitFrame frame) {
  ObjectPoseEstimate invalid;
  invalid.utime = frame.utime;
  // Every frame is buffered: with the camera looking at the object, the
  // target hardly moves in the image, yet its view direction changes, and
  // that rotation is what resolves the structure of a small object.
  init_frames_.push_back(std::move(frame));
  while (init_frames_.size() > static_cast<std::size_t>(options_.init_frames)) init_frames_.pop_front();
  const InitFrame& cur = init_frames_.back();
  std::vector<int64_t> ids;
  while (init_frames_.size() >= 2) {
    ids.clear();
    for (const auto& [id, z] : init_frames_.front().observations) {
      if (cur.observations.count(id)) ids.push_back(id);
    }
    if (static_cast<int>(ids.size()) >= options_.min_init_features) break;
    init_frames_.pop_front();
  }
  if (init_frames_.size() < static_cast<std::size_t>(options_.init_frames)) return invalid;
  const InitFrame& ref = init_frames_.front();

  std::vector<cv::Point2d> p0, p1;
  for (int64_t id : ids) {
    const Eigen::Vector2d& a = ref.observations.at(id);
    const Eigen::Vector2d& b = cur.observations.at(id);
    p0.emplace_back(a.x(), a.y());
    p1.emplace_back(b.x(), b.y());
  }
  const double threshold = options_.ransac_threshold_px / options_.focal_length_px;
  cv::Mat inlier_mask;
  cv::theRNG().state = 1;  // RANSAC samples: the same input gives the same track
  const cv::Mat E = cv::findEssentialMat(p0, p1, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999, threshold, inlier_mask);
  if (E.rows != 3 || E.cols != 3) return invalid;
  cv::Mat R_cv, t_cv;
  cv::recoverPose(E, p0, p1, R_cv, t_cv, 1.0, cv::Point2d(0, 0), inlier_mask);
  Eigen::Matrix3d R_C0toC1;
  Eigen::Vector3d p_C0inC1;
  cv::cv2eigen(R_cv, R_C0toC1);
  cv::cv2eigen(t_cv, p_C0inC1);

  std::vector<double> parallax;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!inlier_mask.at<uchar>(static_cast<int>(i))) continue;
    parallax.push_back(angle_between(R_C0toC1 * homogeneous(ref.observations.at(ids[i])),
                                     homogeneous(cur.observations.at(ids[i]))));
  }
  if (static_cast<int>(parallax.size()) < options_.min_init_features ||
      median(parallax) < options_.min_init_parallax_deg * kDegToRad) {
    return invalid;
  }

  // Two-view reconstruction in the reference camera C0 (|p_C0inC1| = 1):
  // the depths of the common features.
  std::map<int64_t, double> depths;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (!inlier_mask.at<uchar>(static_cast<int>(i))) continue;
    const std::optional<Eigen::Vector3d> X = triangulate(homogeneous(ref.observations.at(ids[i])),
                                                         homogeneous(cur.observations.at(ids[i])), R_C0toC1, p_C0inC1);
    if (X) depths[ids[i]] = X->z();
  }
  if (static_cast<int>(depths.size()) < options_.min_init_features) return invalid;

  // A BA over all buffered frames from these depths, the frames after the
  // reference posed by PnP in turn: a small object spans a narrow field of
  // view, where two views hardly separate rotation from translation.
  // Returns the squared reprojection errors (normalized units) of the
  // observations its outlier removal kept; the state is left in the
  // members.
  using Fit = std::map<std::pair<int64_t, int64_t>, double>;  // (feature, utime) -> |r|^2
  const auto solve_from = [&](const std::map<int64_t, double>& start_depths) -> std::optional<Fit> {
    poses_.clear();
    features_.clear();
    window_ = {ref.utime};
    poses_[ref.utime] = Pose{};
    for (const auto& [id, depth] : start_depths) {
      Feature& f = features_[id];
      f.p_FinO = depth * homogeneous(ref.observations.at(id));  // O = C0 until the normalisation
      f.in_ba = true;
      for (const InitFrame& frame : init_frames_) {
        const auto z = frame.observations.find(id);
        if (z != frame.observations.end()) f.observations[frame.utime] = z->second;
      }
    }
    for (std::size_t k = 1; k < init_frames_.size(); ++k) {
      const Pose pose = predict_pose(init_frames_[k].observations);
      window_.push_back(init_frames_[k].utime);
      poses_[init_frames_[k].utime] = pose;
    }
    // Only the reference pose is fixed; the scale freedom is removed by
    // the normalisation below.
    if (!solve_window(1, kInitIterationFactor * options_.max_iterations)) return std::nullopt;
    if (remove_outliers() > 0 && !solve_window(1, kInitIterationFactor * options_.max_iterations)) return std::nullopt;
    Fit fit;
    for (const auto& [id, f] : features_) {
      for (const auto& [utime, z] : f.observations) {
        const double e = reprojection_error_px(f, utime, z) / options_.focal_length_px;
        fit[{id, utime}] = e * e;
      }
    }
    return fit;
  };
  // Under the near-affine projection of a small object the depth-reversed
  // structure (Necker reversal: depths mirrored about their median) fits
  // almost as well and the BA cannot leave it; both are solved and the
  // cheaper kept.
  const std::optional<Fit> fit = solve_from(depths);
  const auto kept_poses = poses_;
  const auto kept_features = features_;
  const auto kept_window = window_;
  std::vector<double> depth_values;
  for (const auto& [id, depth] : depths) depth_values.push_back(depth);
  const double median_depth = median(depth_values);
  std::map<int64_t, double> reversed;
  for (const auto& [id, depth] : depths) {
    const double mirrored = 2.0 * median_depth - depth;
    if (mirrored > 0.0) reversed[id] = mirrored;
  }
  const std::optional<Fit> reversed_fit =
      static_cast<int>(reversed.size()) >= options_.min_init_features ? solve_from(reversed) : std::nullopt;
  if (!fit && !reversed_fit) return invalid;
  // Commit only if the whole buffer prefers one structure clearly: the sum
  // of squared errors over the observations both kept (each hypothesis'
  // outlier removal alone would favour the one that discarded the views it
  // fits worst), in units of the noise variance per coordinate estimated
  // from the better one, is a chi-square difference. A small gap means the
  // buffer has not seen enough perspective yet: wait.
  bool keep_first = !reversed_fit;
  if (fit && reversed_fit) {
    double sum_first = 0.0, sum_reversed = 0.0;
    int common = 0;
    for (const auto& [key, e2] : *fit) {
      const auto other = reversed_fit->find(key);
      if (other == reversed_fit->end()) continue;
      sum_first += e2;
      sum_reversed += other->second;
      ++common;
    }
    keep_first = sum_first <= sum_reversed;
    const double min_sigma = kMinNoisePx / options_.focal_length_px;
    const double variance = std::max(std::min(sum_first, sum_reversed) / std::max(2 * common, 1), min_sigma * min_sigma);
    if (std::abs(sum_first - sum_reversed) / variance < options_.init_min_chi2_gap) return invalid;
  }
  if (keep_first) {
    poses_ = kept_poses;
    features_ = kept_features;
    window_ = kept_window;
  }
  if (static_cast<int>(features_.size()) < options_.min_init_features) return invalid;
  // Points on (nearly) one plane, e.g. one face of the box, admit a family
  // of structures under the near-affine view, not just the two above: wait
  // for points off that plane.
  if (structure_thickness(features_) < options_.init_min_thickness) return invalid;

  // Fig. 5: the surface along the centre ray is at the median distance of
  // the features angularly nearest to the ray; that distance becomes 1.
  std::vector<std::pair<double, int64_t>> by_angle;
  for (const auto& [id, f] : features_) by_angle.emplace_back(angle_between(f.p_FinO, ref.centre_ray), id);
  std::sort(by_angle.begin(), by_angle.end());
  by_angle.resize(std::min(by_angle.size(), static_cast<std::size_t>(options_.reference_features)));
  std::vector<double> distances;
  std::vector<int64_t> reference_ids;
  for (const auto& [angle, id] : by_angle) {
    const Feature& f = features_.at(id);
    distances.push_back(f.p_FinO.norm());
    reference_ids.push_back(id);
  }
  const double d_ref = median(distances);
  if (!(d_ref > 0.0) || !std::isfinite(d_ref)) return invalid;

  // O: orientation of C0, origin at d_ref along the ray; unit = d_ref. A
  // pose T_C0toC becomes R_OtoC = R_C0toC, pbar_OinC = R_C0toC u + p_C0inC/d_ref.
  for (auto& [utime, pose] : poses_) {
    pose.pbar_OinC = pose.q_OtoC * ref.centre_ray + pose.pbar_OinC / d_ref;
  }
  for (auto& [id, f] : features_) f.p_FinO = f.p_FinO / d_ref - ref.centre_ray;

  InitFacts facts;
  facts.track_id = next_track_id_++;
  facts.reference_utime = ref.utime;
  facts.init_utime = cur.utime;
  facts.centre_ray_C0 = ref.centre_ray;
  facts.reference_feature_ids = reference_ids;
  init_facts_ = facts;
  ++counters_.initialisations;
  tracking_ = true;
  const ObjectPoseEstimate estimate = make_estimate(cur.utime, cur.observations);
  init_frames_.clear();
  return estimate;
}

ObjectPoseEstimate ObjectTracker::track(int64_t utime, const Observations& raw_obs) {
  ObjectPoseEstimate invalid;
  invalid.utime = utime;
  const auto lose_track = [&] {
    ++counters_.track_losses;
    reset();
    return invalid;
  };
  const Pose predicted = predict_pose(with_aliases(raw_obs));
  const Observations obs = associate(raw_obs, predicted);
  int tracked = 0;
  for (const auto& [id, z] : obs) {
    const auto it = features_.find(id);
    if (it != features_.end() && it->second.in_ba) ++tracked;
  }
  if (tracked < options_.min_track_features) return lose_track();

  const auto t0 = std::chrono::steady_clock::now();
  add_observations(utime, obs, predicted);
  bool solved = solve_window(2, options_.max_iterations);
  // The second removal catches what the re-solve pushed out (e.g. a new
  // point behind a camera); it changes no estimate, so no third solve.
  if (solved && remove_outliers() > 0) {
    solved = solve_window(2, options_.max_iterations);
    remove_outliers();
  }
  last_solve_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!solved) return lose_track();

  const ObjectPoseEstimate estimate = make_estimate(utime, obs);
  if (!estimate.valid) return lose_track();
  slide_window();
  return estimate;
}

ObjectTracker::Observations ObjectTracker::with_aliases(const Observations& obs) const {
  Observations out;
  for (const auto& [id, z] : obs) {
    const auto alias = aliases_.find(id);
    out[alias == aliases_.end() ? id : alias->second] = z;
  }
  return out;
}

ObjectTracker::Observations ObjectTracker::associate(const Observations& raw_obs, const Pose& pose) {
  Observations obs = with_aliases(raw_obs);
  // A front end gives a point a fresh id when its track breaks, though it
  // is the same surface point. A new id whose observation falls on the
  // projection of exactly one BA point not seen in this frame continues
  // that point: the points then live as long as they are visible, and the
  // structure (and with it the gauge and scale) is not handed over from
  // one short-lived generation of points to the next.
  const double gate = options_.reassociation_px / options_.focal_length_px;
  std::vector<std::pair<int64_t, Eigen::Vector2d>> lost;
  for (const auto& [id, f] : features_) {
    if (!f.in_ba || obs.count(id)) continue;
    const Eigen::Vector3d p_FinC = pose.q_OtoC * f.p_FinO + pose.pbar_OinC;
    if (p_FinC.z() > 0.0) lost.emplace_back(id, p_FinC.head<2>() / p_FinC.z());
  }
  for (const auto& [raw_id, z] : raw_obs) {
    if (aliases_.count(raw_id) || features_.count(raw_id)) continue;
    double best = std::numeric_limits<double>::infinity();
    double second = best;
    int64_t best_id = -1;
    for (const auto& [id, projection] : lost) {
      const double d = (projection - z).norm();
      if (d < best) {
        second = best;
        best = d;
        best_id = id;
      } else if (d < second) {
        second = d;
      }
    }
    // Unambiguous: no other point within twice the gate.
    if (best > gate || second < 2.0 * gate || obs.count(best_id)) continue;
    aliases_[raw_id] = best_id;
    obs.erase(raw_id);
    obs[best_id] = z;
  }
  return obs;
}

ObjectTracker::Pose ObjectTracker::predict_pose(const Observations& obs) const {
  const Pose& last = poses_.at(window_.back());
  std::vector<cv::Point3d> object_points;
  std::vector<cv::Point2d> image_points;
  for (const auto& [id, z] : obs) {
    const auto it = features_.find(id);
    if (it == features_.end() || !it->second.in_ba) continue;
    const Eigen::Vector3d& p = it->second.p_FinO;
    object_points.emplace_back(p.x(), p.y(), p.z());
    image_points.emplace_back(z.x(), z.y());
  }
  cv::Mat rvec, tvec;
  cv::Mat R_last;
  cv::eigen2cv(Eigen::Matrix3d(last.q_OtoC.toRotationMatrix()), R_last);
  cv::Rodrigues(R_last, rvec);
  cv::eigen2cv(last.pbar_OinC, tvec);
  // A local refinement from the last pose, not a RANSAC PnP: on a small
  // object the minimal solutions jump between the near-ambiguous (depth
  // reversed) poses, while 50 ms of motion stays in the right basin.
  if (object_points.size() < 4) return last;
  cv::solvePnPRefineLM(object_points, image_points, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec);
  cv::Mat R_cv;
  cv::Rodrigues(rvec, R_cv);
  Eigen::Matrix3d R_OtoC;
  Eigen::Vector3d pbar_OinC;
  cv::cv2eigen(R_cv, R_OtoC);
  cv::cv2eigen(tvec, pbar_OinC);
  if (!R_OtoC.allFinite() || !pbar_OinC.allFinite()) return last;
  return Pose{Eigen::Quaterniond(R_OtoC), pbar_OinC};
}

void ObjectTracker::add_observations(int64_t utime, const Observations& obs, const Pose& pose) {
  window_.push_back(utime);
  poses_[utime] = pose;
  for (const auto& [id, z] : obs) features_[id].observations[utime] = z;
  // A feature joins the BA once it has enough views and parallax; its
  // point then comes from its oldest view in the window and the current.
  for (auto& [id, f] : features_) {
    if (f.in_ba || !obs.count(id) || static_cast<int>(f.observations.size()) < options_.min_feature_observations) {
      continue;
    }
    if (feature_parallax_rad(f) < options_.min_feature_parallax_deg * kDegToRad) continue;
    const auto& [first_utime, first_z] = *f.observations.begin();
    const Pose& a = poses_.at(first_utime);
    const Eigen::Matrix3d R_OtoCa = a.q_OtoC.toRotationMatrix();
    const Eigen::Matrix3d R_CatoC = pose.q_OtoC.toRotationMatrix() * R_OtoCa.transpose();
    const Eigen::Vector3d p_CainC = pose.pbar_OinC - R_CatoC * a.pbar_OinC;
    const std::optional<Eigen::Vector3d> X = triangulate(homogeneous(first_z), homogeneous(obs.at(id)), R_CatoC, p_CainC);
    if (!X) continue;
    f.p_FinO = R_OtoCa.transpose() * (*X - a.pbar_OinC);
    // Only a point that fits all its views joins: a wrong one (a mismatch,
    // or a two-view depth off in a bad geometry) would pull the poses before
    // the outlier removal sees it, and take good points with it.
    f.in_ba = std::all_of(f.observations.begin(), f.observations.end(), [&](const auto& o) {
      return reprojection_error_px(f, o.first, o.second) <= options_.outlier_threshold_px;
    });
  }
}

bool ObjectTracker::solve_window(int num_fixed_poses, int max_iterations) {
  // Declared before the problem, which uses but does not own them.
  ceres::EigenQuaternionManifold quaternion_manifold;
  const double loss_scale = options_.robust_loss_px / options_.focal_length_px;
  std::unique_ptr<ceres::LossFunction> loss;
  if (options_.robust_loss == "cauchy") {
    loss = std::make_unique<ceres::CauchyLoss>(loss_scale);
  } else {
    loss = std::make_unique<ceres::HuberLoss>(loss_scale);
  }
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);

  const auto add_pose = [&](Pose& pose) {
    if (!problem.HasParameterBlock(pose.q_OtoC.coeffs().data())) {
      problem.AddParameterBlock(pose.q_OtoC.coeffs().data(), 4, &quaternion_manifold);
      problem.AddParameterBlock(pose.pbar_OinC.data(), 3);
    }
  };
  for (auto& [id, f] : features_) {
    if (!f.in_ba) continue;
    for (const auto& [utime, z] : f.observations) {
      Pose& pose = poses_.at(utime);
      add_pose(pose);
      problem.AddResidualBlock(new ceres::AutoDiffCostFunction<PointReprojection, 2, 4, 3, 3>(new PointReprojection(z)),
                               loss.get(), pose.q_OtoC.coeffs().data(), pose.pbar_OinC.data(), f.p_FinO.data());
    }
  }
  if (problem.NumResidualBlocks() == 0) return false;
  // Gauge: the oldest window poses and the retired ones.
  for (auto& [utime, pose] : poses_) {
    const auto pos = std::find(window_.begin(), window_.end(), utime);
    if ((pos == window_.end() || pos - window_.begin() < num_fixed_poses) &&
        problem.HasParameterBlock(pose.q_OtoC.coeffs().data())) {
      problem.SetParameterBlockConstant(pose.q_OtoC.coeffs().data());
      problem.SetParameterBlockConstant(pose.pbar_OinC.data());
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_SCHUR;
  solver_options.max_num_iterations = max_iterations;
  solver_options.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  if (!summary.IsSolutionUsable()) return false;
  for (auto& [utime, pose] : poses_) {
    if (!pose.q_OtoC.coeffs().allFinite() || !pose.pbar_OinC.allFinite()) return false;
    pose.q_OtoC.normalize();
  }
  return true;
}

int ObjectTracker::remove_outliers() {
  int removed = 0;
  for (auto it = features_.begin(); it != features_.end();) {
    Feature& f = it->second;
    if (!f.in_ba) {
      ++it;
      continue;
    }
    int rejected = 0;
    int kept = 0;
    for (auto o = f.observations.begin(); o != f.observations.end();) {
      if (reprojection_error_px(f, o->first, o->second) > options_.outlier_threshold_px) {
        o = f.observations.erase(o);
        ++rejected;
      } else {
        ++o;
        ++kept;
      }
    }
    removed += rejected;
    // Most views disagree: the point itself is wrong.
    if (rejected > 0 && kept <= rejected) {
      it = features_.erase(it);
    } else {
      ++it;
    }
  }
  counters_.removed_outlier_observations += removed;
  return removed;
}

void ObjectTracker::slide_window() {
  const int64_t current = window_.back();
  if (window_.size() > static_cast<std::size_t>(options_.window_size) && !is_keyframe(window_.end()[-2], window_.end()[-3])) {
    drop_frame(window_.end()[-2]);
  }
  while (window_.size() > static_cast<std::size_t>(options_.window_size)) {
    const int64_t oldest = window_.front();
    window_.pop_front();
    // The leaving pose is retired, not forgotten: it stays (constant) with
    // its views of the BA points while they live, so those views keep
    // constraining the points and, through them, carry the gauge. Freezing
    // the points instead would keep their early (e.g. the initialisation's)
    // errors for good.
    for (auto& [id, f] : features_) {
      if (!f.in_ba) f.observations.erase(oldest);
    }
  }
  if (options_.max_retired_poses > 0) {
    // poses_ is ordered by utime and every retired pose is older than the
    // window: the first ones are the oldest retired.
    const std::size_t retired = poses_.size() - window_.size();
    for (std::size_t k = static_cast<std::size_t>(options_.max_retired_poses); k < retired; ++k) {
      const int64_t oldest = poses_.begin()->first;
      for (auto& [id, f] : features_) f.observations.erase(oldest);
      poses_.erase(poses_.begin());
    }
  }
  // Feature ids are never reused after a track loss, so a candidate not seen
  // now can never join, and a BA feature without views in the window is gone.
  std::set<int64_t> referenced(window_.begin(), window_.end());
  for (auto it = features_.begin(); it != features_.end();) {
    const Feature& f = it->second;
    const bool seen_now = f.observations.count(current) > 0;
    if ((!f.in_ba && !seen_now) || f.observations.lower_bound(window_.front()) == f.observations.end()) {
      it = features_.erase(it);
    } else {
      for (const auto& [utime, z] : f.observations) referenced.insert(utime);
      ++it;
    }
  }
  for (auto it = poses_.begin(); it != poses_.end();) it = referenced.count(it->first) ? std::next(it) : poses_.erase(it);
}

bool ObjectTracker::is_keyframe(int64_t utime, int64_t previous_utime) const {
  const Pose& a = poses_.at(previous_utime);
  const Pose& b = poses_.at(utime);
  const Eigen::Matrix3d R_a = a.q_OtoC.toRotationMatrix();
  const Eigen::Matrix3d R_b = b.q_OtoC.toRotationMatrix();
  const Eigen::Vector3d p_CainO = -R_a.transpose() * a.pbar_OinC;
  const Eigen::Vector3d p_CbinO = -R_b.transpose() * b.pbar_OinC;
  return rotation_angle_between(R_a, R_b) >= options_.keyframe_rotation_deg * kDegToRad ||
         (p_CbinO - p_CainO).norm() >= options_.keyframe_baseline;
}

void ObjectTracker::drop_frame(int64_t utime) {
  for (auto& [id, f] : features_) f.observations.erase(utime);
  window_.erase(std::find(window_.begin(), window_.end(), utime));
  poses_.erase(utime);
}

void ObjectTracker::reset() {
  tracking_ = false;
  window_.clear();
  poses_.clear();
  features_.clear();
  aliases_.clear();
  init_frames_.clear();
}

double ObjectTracker::feature_parallax_rad(const Feature& f) const {
  const auto& [first_utime, first_z] = *f.observations.begin();
  const auto& [last_utime, last_z] = *f.observations.rbegin();
  const Eigen::Matrix3d R_CtoCa =
      poses_.at(first_utime).q_OtoC.toRotationMatrix() * poses_.at(last_utime).q_OtoC.toRotationMatrix().transpose();
  return angle_between(homogeneous(first_z), R_CtoCa * homogeneous(last_z));
}

double ObjectTracker::reprojection_error_px(const Feature& f, int64_t utime, const Eigen::Vector2d& z) const {
  const Pose& pose = poses_.at(utime);
  const Eigen::Vector3d p_FinC = pose.q_OtoC * f.p_FinO + pose.pbar_OinC;
  if (!(p_FinC.z() > 0.0)) return std::numeric_limits<double>::infinity();
  return (p_FinC.head<2>() / p_FinC.z() - z).norm() * options_.focal_length_px;
}

ObjectPoseEstimate ObjectTracker::make_estimate(int64_t utime, const Observations& obs) const {
  ObjectPoseEstimate e;
  e.utime = utime;
  e.track_id = init_facts_ ? init_facts_->track_id : 0;
  const Pose& pose = poses_.at(utime);
  double sum_sq = 0.0;
  for (const auto& [id, z] : obs) {
    const auto it = features_.find(id);
    if (it == features_.end() || !it->second.in_ba || !it->second.observations.count(utime)) continue;
    const double err = reprojection_error_px(it->second, utime, z);
    sum_sq += err * err;
    ++e.num_features;
  }
  e.reprojection_rms_px = e.num_features > 0 ? std::sqrt(sum_sq / e.num_features) : 0.0;
  const Eigen::Matrix3d R_OtoC = pose.q_OtoC.toRotationMatrix();
  e.pbar_OinC = pose.pbar_OinC;
  e.valid = e.num_features >= options_.min_track_features && e.reprojection_rms_px <= options_.max_reprojection_rms_px &&
            R_OtoC.allFinite() && e.pbar_OinC.allFinite();
  if (e.valid) e.q_OtoC = rot_to_quat(R_OtoC);
  return e;
}

}  // namespace vimot

#include "procs/target_filter/target_filter_node.h"

#include <cmath>
#include <stdexcept>

#include "common/estimator/state_helper.h"
#include "common/eval/initial_estimate.h"
#include "common/eval/nav_state_of.h"
#include "common/eval/vins_config.h"
#include "common/target/target_model.h"
#include "common/target/target_output.h"

namespace vimot {

namespace {

target::TargetUpdateMode parse_mode(const std::string& s) {
  if (s == "skf") return target::TargetUpdateMode::kSkf;
  if (s == "ekf") return target::TargetUpdateMode::kEkf;
  if (s == "off") return target::TargetUpdateMode::kOff;
  throw std::invalid_argument("target.mode must be skf, ekf, off or none, not '" + s + "'");
}

target::TargetRepresentation parse_representation(const std::string& s) {
  if (s == "local") return target::TargetRepresentation::kLocal;
  if (s == "global") return target::TargetRepresentation::kGlobal;
  throw std::invalid_argument("target.representation must be local or global, not '" + s + "'");
}

}  // namespace

void target_options_from_config(const Config& cfg, TargetFilterNodeOptions* options) {
  target::TargetFilterOptions& t = options->target;
  const std::string mode = cfg.get_or<std::string>("target.mode", "skf");
  options->target_enabled = mode != "none";
  if (options->target_enabled) t.mode = parse_mode(mode);
  t.representation = parse_representation(cfg.get_or<std::string>(
      "target.representation", t.representation == target::TargetRepresentation::kLocal ? "local" : "global"));
  t.sigma_t = cfg.get_or<double>("target.sigma_t", t.sigma_t);
  t.planar = cfg.get_or<bool>("target.planar", t.planar);
  t.chi2_multiplier = cfg.get_or<double>("target.chi2_multiplier", t.chi2_multiplier);
  t.min_clone_times = cfg.get_or<int>("target.min_clone_times", t.min_clone_times);
  t.max_target_points = cfg.get_or<int>("target.points.max", t.max_target_points);
  t.point_init_clone_times = cfg.get_or<int>("target.points.init_clone_times", t.point_init_clone_times);
  t.point_max_lost_frames = cfg.get_or<int>("target.points.max_lost_frames", t.point_max_lost_frames);
  t.init_mode = target::parse_init_mode(cfg.get_or<std::string>("target.init.mode", target::to_string(t.init_mode)));
  t.feature_init.frames = cfg.get_or<int>("target.init.frames", t.feature_init.frames);
  t.feature_init.min_points = cfg.get_or<int>("target.init.min_points", t.feature_init.min_points);
  t.feature_init.max_point_distance =
      cfg.get_or<double>("target.init.max_point_distance", t.feature_init.max_point_distance);
  t.feature_init.sigma_w = cfg.get_or<double>("target.init.sigma_w", t.feature_init.sigma_w);
  t.init_sigmas.theta = cfg.get_or<double>("target.init_sigmas.theta", t.init_sigmas.theta);
  t.init_sigmas.p = cfg.get_or<double>("target.init_sigmas.p", t.init_sigmas.p);
  t.init_sigmas.v = cfg.get_or<double>("target.init_sigmas.v", t.init_sigmas.v);
  t.init_sigmas.w = cfg.get_or<double>("target.init_sigmas.w", t.init_sigmas.w);
  options->prediction_horizon_s = cfg.get_or<double>("target.prediction_horizon_s", options->prediction_horizon_s);
  if (!(options->prediction_horizon_s >= 0.0) || !std::isfinite(options->prediction_horizon_s)) {
    throw std::invalid_argument("target.prediction_horizon_s must be finite and >= 0");
  }
}

TargetFilterNodeOptions node_options_from_config(const Config& cfg) {
  const Config vins = cfg.has("vins_config")
                          ? Config::load_file(cfg.resolve_path(cfg.get<std::string>("vins_config")))
                          : cfg;
  TargetFilterNodeOptions options;
  options.vio = eval::vio_options_from_config(vins);
  const eval::VinsStartOptions start = eval::start_options_from_config(vins);
  options.init_from_ground_truth = start.mode == estimator::InitMode::kGroundTruth;
  options.perturb_seed = start.perturb_seed;
  options.publish_imu_rate = cfg.get_or<bool>("output.imu_rate", options.publish_imu_rate);
  target_options_from_config(cfg, &options);
  return options;
}

TargetStateEstimate target_state_of(const estimator::VioEstimator& estimator, const target::TargetFilter& filter) {
  return target::target_state_estimate(estimator.state_utime(), filter.options().representation, filter.value(),
                                       filter.covariance(), target::imu_pose(estimator.imu_value()),
                                       static_cast<int>(filter.points().size()));
}

TargetPosePrediction target_prediction_of(const estimator::VioEstimator& estimator,
                                          const target::TargetFilter& filter, double horizon_s) {
  const target::PoseValue imu = target::imu_pose(estimator.imu_value());
  const target::TargetNoise noise = filter.options().noise();
  target::TargetPrediction pred;
  if (filter.options().representation == target::TargetRepresentation::kLocal) {
    const estimator::State& st = estimator.state();
    const Eigen::MatrixXd P = estimator::StateHelper::marginal_covariance(
        st, {st.imu()->pose()->q(), st.imu()->pose()->p(), filter.target()});
    pred = target::predict_local_in_global(imu, filter.value(), P, horizon_s, noise);
  } else {
    pred = target::predict_global(filter.value(), filter.covariance(), horizon_s, noise);
  }
  return target::target_pose_prediction(estimator.state_utime(), horizon_s, pred, imu);
}

namespace {
VinsNodeOptions vins_node_options(const TargetFilterNodeOptions& o) {
  VinsNodeOptions v;
  v.vio = o.vio;
  v.init_from_ground_truth = o.init_from_ground_truth;
  v.perturb_seed = o.perturb_seed;
  v.publish_imu_rate = o.publish_imu_rate;
  v.max_queued_frames = o.max_queued_frames;
  return v;
}
}  // namespace

TargetFilterNode::TargetFilterNode(const TargetFilterNodeOptions& options, Callbacks callbacks)
    : options_(options),
      callbacks_(std::move(callbacks)),
      vins_(
          vins_node_options(options),
          [this](const NavState& s) {
            if (callbacks_.on_nav_state) callbacks_.on_nav_state(s);
          },
          [this](const VinsEvent& e) {
            if (callbacks_.on_event) callbacks_.on_event(e);
          }) {
  if (options_.target_enabled) {
    // A start from the truth is perturbed with the robot's seed, as in vimot-target-eval.
    target::TargetFilterOptions target = options_.target;
    target.init_perturb_seed = options_.perturb_seed;
    filter_ = std::make_unique<target::TargetFilter>(vins_.mutable_estimator(), target);
  }
  vins_.set_frame_hooks([this](const CameraFrame& frame) { before_frame(frame); }, [this] { after_update(); });
}

TargetFilterNode::~TargetFilterNode() = default;

void TargetFilterNode::on_imu(const ImuData& imu) { vins_.on_imu(imu); }

void TargetFilterNode::on_frame(const CameraFrame& frame) { vins_.on_frame(frame); }

void TargetFilterNode::flush() { vins_.flush(); }

void TargetFilterNode::on_ground_truth(const GroundTruth& truth) {
  if (filter_ && truth.has_target && options_.target.init_mode == target::TargetInitMode::kGroundTruth) {
    truths_[truth.utime] = truth;
    const int64_t keep_from = truth.utime - static_cast<int64_t>(options_.ground_truth_buffer_s * 1e6);
    while (!truths_.empty() && truths_.begin()->first < keep_from) truths_.erase(truths_.begin());
  }
  vins_.on_ground_truth(truth);
}

void TargetFilterNode::before_frame(const CameraFrame& frame) {
  if (!filter_ || filter_->initialized()) return;
  // The filter initialises the target from the truth at the frame's utime.
  const auto it = truths_.find(frame.utime);
  if (it != truths_.end()) filter_->set_ground_truth(it->second);
}

void TargetFilterNode::after_update() {
  if (!target_initialized()) return;
  const estimator::VioEstimator& est = vins_.estimator();
  if (callbacks_.on_target_state) callbacks_.on_target_state(target_state_of(est, *filter_));
  if (callbacks_.on_target_prediction) {
    callbacks_.on_target_prediction(target_prediction_of(est, *filter_, options_.prediction_horizon_s));
  }
}

}  // namespace vimot

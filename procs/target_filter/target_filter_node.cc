#include "procs/target_filter/target_filter_node.h"

#include <cmath>
#include <stdexcept>

#include "common/estimator/initial_estimate.h"
#include "common/estimator/nav_state_of.h"
#include "common/estimator/state_helper.h"
#include "common/estimator/vins_config.h"
#include "common/target/target_filter_config.h"
#include "common/target/target_model.h"
#include "common/target/target_output.h"

namespace vimot {

void target_options_from_config(const Config& cfg, TargetFilterNodeOptions* options) {
  const target::TargetSection t = target::target_section_from_config(cfg);
  options->target = t.filter;
  options->target_enabled = t.enabled;
  options->prediction_horizon_s = t.prediction_horizon_s;
}

TargetFilterNodeOptions node_options_from_config(const Config& cfg) {
  // Without vins_config, the vins config's keys are in this file itself.
  const bool separate_vins = cfg.has("vins_config");
  const std::vector<std::string>& vins_keys = estimator::vins_config_keys();
  std::vector<std::string> keys = {"vins_config", "channels", "output", "target"};
  if (!separate_vins) keys.insert(keys.end(), vins_keys.begin(), vins_keys.end());
  cfg.check_keys("", keys);
  cfg.check_keys("output", {"imu_rate"});
  const Config vins =
      separate_vins ? Config::load_file(cfg.resolve_path(cfg.get<std::string>("vins_config"))) : cfg;
  if (separate_vins) vins.check_keys("", vins_keys);
  TargetFilterNodeOptions options;
  options.vio = estimator::vio_options_from_config(vins);
  const estimator::VinsStartOptions start = estimator::start_options_from_config(vins);
  options.init_from_ground_truth = start.mode == estimator::InitMode::kGroundTruth;
  options.perturb_seed = start.perturb_seed;
  options.publish_imu_rate = cfg.get_or<bool>("output.imu_rate", options.publish_imu_rate);
  target_options_from_config(cfg, &options);
  options.input = input_guard_options_from_config(vins);
  check_bridge_options(options.input, options.vio, vins);
  return options;
}

TargetStateEstimate target_state_of(const estimator::VioEstimator& estimator, const target::TargetFilter& filter) {
  return target::target_state_estimate(estimator.state_utime(), filter.options().representation, filter.value(),
                                       filter.covariance(), target::imu_pose(estimator.imu_value()),
                                       static_cast<int>(filter.points().size()), filter.starts());
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
  v.input = o.input;
  v.checkpoint_path = o.checkpoint_path;
  v.catch_up_log = o.catch_up_log;
  v.catch_up_channels = o.catch_up_channels;
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
          [this](const NodeEvent& e) {
            if (callbacks_.on_event) callbacks_.on_event(e);
          }) {
  if (options_.target_enabled) {
    // A start from the truth is perturbed with the robot's seed, as in vimot-target-eval.
    target::TargetFilterOptions target = options_.target;
    target.init_perturb_seed = options_.perturb_seed;
    filter_ = std::make_unique<target::TargetFilter>(vins_.mutable_estimator(), target);
    checkpoint_ = std::make_unique<target::TargetCheckpoint>(*filter_);
    vins_.set_checkpoint_extension(checkpoint_.get());
  }
  vins_.set_frame_hooks([this](const CameraFrame& frame) { before_frame(frame); }, [this] { after_update(); });
  vins_.set_ground_truth_hook([this](const GroundTruth& truth) { keep_truth(truth); });
}

TargetFilterNode::~TargetFilterNode() = default;

void TargetFilterNode::on_imu(const ImuData& imu) { vins_.on_imu(imu); }

void TargetFilterNode::on_frame(const CameraFrame& frame) { vins_.on_frame(frame); }

void TargetFilterNode::flush() { vins_.flush(); }

void TargetFilterNode::on_ground_truth(const GroundTruth& message) { vins_.on_ground_truth(message); }

void TargetFilterNode::keep_truth(const GroundTruth& truth) {
  if (filter_ && truth.has_target && options_.target.init_mode == target::TargetInitMode::kGroundTruth) {
    truths_[truth.utime] = truth;
    const int64_t keep_from = truth.utime - static_cast<int64_t>(options_.ground_truth_buffer_s * 1e6);
    while (!truths_.empty() && truths_.begin()->first < keep_from) truths_.erase(truths_.begin());
  }
}

void TargetFilterNode::before_frame(const CameraFrame& frame) {
  if (!filter_ || filter_->initialized()) return;
  // init.mode ground_truth: the target starts from the truth at the frame's utime (features: nothing buffered).
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

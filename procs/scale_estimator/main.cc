// scale_estimator: metric scale of a monocularly tracked object (scale
// paper, Eq. 8-21) as an LCM process. Subscribes VINS_STATE (camera-rate
// updated states) and OBJECT_POSE_UPTOSCALE; publishes SCALE_ESTIMATE per
// estimate and, once a scale is accepted, OBJECT_POSE_METRIC per pair and
// the object motion filter's OBJECT_STATE and OBJECT_PREDICTION.
// All logic is in ScaleNode / the scale estimator library; this file moves bytes.

#include "common/process/lcm_conversions.h"
#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/scale_estimator/scale_node.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("scale_estimator",
                         "Metric scale of the monocular object tracker's poses:\n"
                         "VINS_STATE + OBJECT_POSE_UPTOSCALE in, SCALE_ESTIMATE, OBJECT_POSE_METRIC and the\n"
                         "filtered object OBJECT_STATE, OBJECT_PREDICTION out.\n"
                         "Configured by config/scale_estimator.yaml (estimator options, calibration file,\n"
                         "channels).",
                         /*config_required=*/true);
  if (!process.init(argc, argv)) return 0;

  const vimot::ScaleNodeOptions options = vimot::scale_node_options_from_config(process.config());
  const std::string scale_channel = process.channel("scale", "SCALE_ESTIMATE");
  const std::string metric_channel = process.channel("metric_object_pose", "OBJECT_POSE_METRIC");
  const std::string state_channel = process.channel("object_state", "OBJECT_STATE");
  const std::string prediction_channel = process.channel("object_prediction", "OBJECT_PREDICTION");
  vimot::ScaleNode node(
      options, [&](const vimot::scale::ScaleResult& r) { process.publish(scale_channel, vimot::to_lcm(r)); },
      [&](const vimot::scale::ObjectPoseInWorld& p) { process.publish(metric_channel, vimot::to_lcm(p)); },
      vimot::report_events_to(process),
      [&](const vimot::TargetStateEstimate& s, const vimot::TargetPosePrediction& p) {
        process.publish(state_channel, vimot::to_lcm(s));
        process.publish(prediction_channel, vimot::to_lcm(p));
      });
  process.subscribe<vimot::nav_state_t>(process.channel("nav_state", "VINS_STATE"),
                                        [&](const vimot::nav_state_t& m) { node.on_nav_state(vimot::from_lcm(m)); });
  process.subscribe<vimot::object_pose_t>(
      process.channel("object_pose", "OBJECT_POSE_UPTOSCALE"),
      [&](const vimot::object_pose_t& m) { node.on_object_pose(vimot::from_lcm(m)); });
  const int status = process.run();
  const vimot::ScaleNodeStats& s = node.stats();
  const vimot::target::ObjectPoseFilterStats& fs = node.filter().stats();
  vimot::log_info(s.pairs, " pairs, ", s.estimates, " estimates, ", s.metric_poses, " metric poses, ",
                  s.object_states, " object states (filter: ", fs.outliers, " outliers, ", fs.reinitializations,
                  " + ", fs.gap_reinitializations, " re-initialisations); dropped: ",
                  s.stale_states, " states, ", s.stale_object_poses, " object poses, ", s.duplicate_or_backwards,
                  " out of order, ", s.rejected_observations, " rejected; ", s.invalid_object_poses,
                  " invalid object poses");
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

// object_tracker: the up-to-scale object tracker (scale paper, Sec. III) as
// an LCM process. Subscribes FEATURES (cam0 observations with the target
// flag), publishes OBJECT_POSE_UPTOSCALE for every accepted frame, valid or
// not. All logic is in ObjectTrackerNode / the tracker library; this file
// moves bytes.

#include "common/process/lcm_conversions.h"
#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/object_tracker/object_tracker_node.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("object_tracker",
                         "Object-region bundle adjustment: FEATURES in, OBJECT_POSE_UPTOSCALE out\n"
                         "(pose of the object in the camera, position up to one scale per track).\n"
                         "Configured by config/object_tracker.yaml (options, channels); without\n"
                         "--config the defaults and the default channel names are used.");
  if (!process.init(argc, argv)) return 0;

  const std::string pose_channel = process.channel("object_pose", "OBJECT_POSE_UPTOSCALE");
  vimot::ObjectTrackerNode node(
      vimot::object_tracker_options_from_config(process.config()),
      [&](const vimot::ObjectPoseEstimate& e) { process.publish(pose_channel, vimot::to_lcm(e)); },
      vimot::report_events_to(process));
  process.subscribe<vimot::features_t>(process.channel("features", "FEATURES"),
                                       [&](const vimot::features_t& m) { node.on_frame(vimot::from_lcm(m)); });
  return process.run();
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

// object_tracker: the up-to-scale object tracker (scale paper, Sec. III) as
// an LCM process. Subscribes FEATURES (cam0 observations with the target
// flag), publishes OBJECT_POSE_UPTOSCALE for every accepted frame, valid or
// not. All logic is in ObjectTrackerNode / the tracker library; this file
// moves bytes.

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "common/process/lcm_conversions.h"
#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/object_tracker/object_tracker_node.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("object_tracker",
                         "Object-region bundle adjustment: FEATURES in, OBJECT_POSE_UPTOSCALE out\n"
                         "(pose of the object in the camera, position up to one scale per track); cam0's\n"
                         "target box (channels.target_box) gives the centre ray at initialisation.\n"
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
  // cam0's box (TARGET_BOX; TARGET_BOX_TRUTH in simulation); without the
  // key no box: the target features' bounding box is used.
  const std::string box_channel = process.channel("target_box", "");
  if (!box_channel.empty()) {
    process.subscribe<vimot::target_box_t>(box_channel, [&](const vimot::target_box_t& m) {
      const std::optional<vimot::frontend::Box> b = vimot::box_of(m);
      if (m.camera_id != 0 || !b) return;
      if (!std::isfinite(b->x_min) || !std::isfinite(b->y_min) || !std::isfinite(b->width) ||
          !std::isfinite(b->height) || b->width < 0.0 || b->height < 0.0) {
        throw std::invalid_argument("target_box_t: non-finite or negative box at utime " + std::to_string(m.utime));
      }
      node.on_box(m.utime, vimot::BoundingBox2d{{b->x_min, b->y_min}, {b->x_min + b->width, b->y_min + b->height}});
    });
  }
  return process.run();
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

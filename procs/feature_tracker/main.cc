// feature_tracker: the visual front end as an LCM process. Subscribes
// CAM_LEFT / CAM_RIGHT (image_t; mono: CAM_LEFT only), the target box
// channel (target_box_t per camera) and, with tracker.target.use_mask, the
// target mask channel (mask_t per camera), publishes FEATURES (features_t) at the
// images' utime. All logic is in FeatureTrackerNode / common/frontend; this
// file moves bytes.

#include <optional>

#include "common/process/image_conversion.h"
#include "common/process/lcm_conversions.h"
#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/feature_tracker/feature_tracker_node.h"
#include "vimot/image_t.hpp"
#include "vimot/mask_t.hpp"
#include "vimot/target_box_t.hpp"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("feature_tracker",
                         "Visual front end: CAM_LEFT / CAM_RIGHT images (+ target boxes) in, FEATURES out.\n"
                         "Configured by config/feature_tracker.yaml (calibration file, stereo or mono,\n"
                         "tracker options, channels).",
                         /*config_required=*/true);
  if (!process.init(argc, argv)) return 0;

  const vimot::FeatureTrackerNodeOptions options = vimot::FeatureTrackerNodeOptions::from_config(process.config());
  const std::string features_channel = process.channel("features", "FEATURES");
  vimot::FeatureTrackerNode node(
      options, [&](const vimot::CameraFrame& f) { process.publish(features_channel, vimot::to_lcm(f)); },
      vimot::report_events_to(process));

  process.subscribe<vimot::image_t>(process.channel("left", "CAM_LEFT"), [&](const vimot::image_t& m) {
    node.on_image(0, m.utime, vimot::grey_from_lcm_image(m));
  });
  if (node.stereo()) {
    process.subscribe<vimot::image_t>(process.channel("right", "CAM_RIGHT"), [&](const vimot::image_t& m) {
      node.on_image(1, m.utime, vimot::grey_from_lcm_image(m));
    });
  }
  process.subscribe<vimot::target_box_t>(
      process.channel("target_box", "TARGET_BOX"),
      [&](const vimot::target_box_t& m) { node.on_box(m.camera_id, m.utime, vimot::box_of(m)); });
  if (node.uses_mask()) {
    process.subscribe<vimot::mask_t>(process.channel("target_mask", "TARGET_MASK"), [&](const vimot::mask_t& m) {
      node.on_mask(m.camera_id, m.utime, vimot::mask_from_lcm(m));
    });
  }
  const int status = process.run();
  node.flush();
  vimot::log_info("tracked ", node.frames_tracked(), " frames, dropped ", node.images_dropped(), " images, ",
                  node.errors(), " errors");
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

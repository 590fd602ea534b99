// object_tracker: the up-to-scale object tracker (scale paper, Sec. III) as
// an LCM process. Subscribes FEATURES (cam0 observations with the target
// flag), publishes OBJECT_POSE_UPTOSCALE for every accepted frame, valid or
// not. All logic is in ObjectTracker; this file moves bytes.

#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "procs/object_tracker/object_tracker.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("object_tracker",
                         "Object-region bundle adjustment: FEATURES in, OBJECT_POSE_UPTOSCALE out\n"
                         "(pose of the object in the camera, position up to one scale per track).\n"
                         "Configured by config/object_tracker.yaml (options, channels); without\n"
                         "--config the defaults and the default channel names are used.");
  if (!process.init(argc, argv)) return 0;

  vimot::ObjectTracker tracker(vimot::object_tracker_options_from_config(process.config()));
  const std::string features_channel = process.channel("features", "FEATURES");
  const std::string pose_channel = process.channel("object_pose", "OBJECT_POSE_UPTOSCALE");
  int64_t last_track_id = 0;
  process.subscribe<vimot::features_t>(features_channel, [&](const vimot::features_t& msg) {
    const vimot::ObjectTrackerCounters before = tracker.counters();
    const vimot::ObjectPoseEstimate estimate = tracker.process(vimot::from_lcm(msg));
    const vimot::ObjectTrackerCounters& after = tracker.counters();
    if (after.rejected_time_backwards > before.rejected_time_backwards) {
      process.report_dropped("FEATURES utime went backwards");
      return;
    }
    if (after.rejected_duplicate_time > before.rejected_duplicate_time) {
      process.report_dropped("FEATURES utime repeated");
      return;
    }
    if (after.dropped_non_finite_observations > before.dropped_non_finite_observations) {
      process.report_dropped("non-finite target observation");
    }
    if (after.track_losses > before.track_losses) vimot::log_info("object track lost at utime ", msg.utime);
    if (estimate.valid && estimate.track_id != last_track_id) {
      last_track_id = estimate.track_id;
      vimot::log_info("object track ", estimate.track_id, " initialised at utime ", msg.utime);
    }
    process.publish(pose_channel, vimot::to_lcm(estimate));
  });
  return process.run();
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

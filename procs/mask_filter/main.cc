// mask_filter: the target box from the segmentation masks as an LCM process.
// Subscribes TARGET_MASK (mask_t, one per camera per frame), publishes
// TARGET_BOX (target_box_t per camera, at the mask's utime). All logic is in
// MaskFilterNode / common/segmentation; this file moves bytes.

#include <algorithm>

#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/mask_filter/mask_filter_node.h"
#include "vimot/mask_t.hpp"
#include "vimot/target_box_t.hpp"

namespace {

vimot::target_box_t to_lcm(const vimot::CameraBox& b) {
  const vimot::segmentation::BoxEstimate& e = b.estimate;
  vimot::target_box_t m{};
  m.utime = e.utime;
  m.camera_id = static_cast<int8_t>(b.camera_id);
  m.raw_valid = e.raw_valid;
  std::copy(e.raw_box.data(), e.raw_box.data() + 4, m.raw_box);
  m.filtered_valid = e.filtered_valid;
  std::copy(e.filtered_box.data(), e.filtered_box.data() + 4, m.filtered_box);
  std::copy(e.filtered_velocity.data(), e.filtered_velocity.data() + 2, m.filtered_velocity);
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) m.filtered_covariance[4 * r + c] = e.filtered_covariance(r, c);
  }
  m.frames_since_raw = e.frames_since_raw;
  return m;
}

int run(int argc, const char* const* argv) {
  vimot::Process process("mask_filter",
                         "Target box filter: TARGET_MASK masks in, TARGET_BOX (raw and Kalman-filtered box\n"
                         "per camera) out. Configured by config/mask_filter.yaml (calibration file, stereo\n"
                         "or mono, morphology, box Kalman filter, channels).",
                         /*config_required=*/true);
  if (!process.init(argc, argv)) return 0;

  const vimot::MaskFilterNodeOptions options = vimot::MaskFilterNodeOptions::from_config(process.config());
  const std::string box_channel = process.channel("target_box", "TARGET_BOX");
  vimot::MaskFilterNode node(
      options, [&](const vimot::CameraBox& b) { process.publish(box_channel, to_lcm(b)); },
      vimot::report_events_to(process));
  process.subscribe<vimot::mask_t>(process.channel("mask", "TARGET_MASK"), [&](const vimot::mask_t& m) {
    node.on_mask(m.camera_id, m.utime, m.width, m.height, m.size, m.data);
  });
  const int status = process.run();
  vimot::log_info("processed ", node.masks_processed(), " masks (", node.detections(), " detections, ",
                  node.rejected(), " gated out, ", node.reinitialised(), " re-initialisations, ",
                  node.tracks_dropped(), " tracks dropped), dropped ", node.masks_dropped(), " masks, ",
                  node.errors(), " errors");
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

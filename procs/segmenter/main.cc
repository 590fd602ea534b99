// segmenter: target masks as an LCM process. Backend onnx: subscribes
// CAM_LEFT / CAM_RIGHT (image_t; mono: CAM_LEFT only); backend truth:
// TARGET_MASK_TRUTH (mask_t from vimot-sim --render). Publishes one mask_t
// per image on TARGET_MASK. All logic is in SegmenterNode /
// common/segmentation; this file moves bytes.

#include <string>

#include "common/process/image_conversion.h"
#include "common/process/node_runner.h"
#include "common/process/process.h"
#include "procs/segmenter/segmenter_node.h"
#include "vimot/image_t.hpp"
#include "vimot/mask_t.hpp"

namespace {

int run(int argc, const char* const* argv) {
  vimot::Process process("segmenter",
                         "Target segmentation: CAM_LEFT / CAM_RIGHT images in (backend onnx: the shipped\n"
                         "network on OpenCV dnn) or TARGET_MASK_TRUTH (backend truth: corrupted true masks),\n"
                         "one mask_t per image on TARGET_MASK out. Configured by config/segmenter.yaml.",
                         /*config_required=*/true);
  if (!process.init(argc, argv)) return 0;

  const vimot::SegmenterNodeOptions options = vimot::SegmenterNodeOptions::from_config(process.config());
  const std::string mask_channel = process.channel("target_mask", "TARGET_MASK");
  vimot::SegmenterNode node(
      options,
      [&](int camera_id, int64_t utime, const cv::Mat& mask) {
        process.publish(mask_channel, vimot::to_lcm_mask(mask, utime, camera_id));
      },
      vimot::report_events_to(process));

  if (node.uses_truth()) {
    process.subscribe<vimot::mask_t>(process.channel("target_mask_truth", "TARGET_MASK_TRUTH"),
                                     [&](const vimot::mask_t& m) {
                                       try {
                                         node.on_true_mask(m.camera_id, m.utime, vimot::mask_from_lcm(m));
                                       } catch (const std::invalid_argument& e) {
                                         process.report_error(e.what());
                                       }
                                     });
  } else {
    const char* channels[2] = {"left", "right"};
    const char* defaults[2] = {"CAM_LEFT", "CAM_RIGHT"};
    for (int cam = 0; cam < node.cameras(); ++cam) {
      process.subscribe<vimot::image_t>(process.channel(channels[cam], defaults[cam]), [&, cam](const vimot::image_t& m) {
        try {
          node.on_image(cam, m.utime, vimot::grey_from_lcm_image(m));
        } catch (const std::invalid_argument& e) {
          process.report_error(e.what());
        }
      });
    }
  }
  const int status = process.run();
  vimot::log_info("published ", node.masks_published(), " masks, ", node.errors(), " errors");
  if (const auto* c = node.corruption_counts()) {
    vimot::log_info("truth corruption: ", c->dropouts, " dropouts (", c->dropout_frames, " frames), ", c->missed,
                    " missed frames, ", c->false_blobs, " false blobs over ", c->frames, " masks");
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

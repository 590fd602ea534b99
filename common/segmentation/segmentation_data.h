#pragma once
// Training and test data for the segmentation network (docs/segmenter.md):
// rendered simulator images (common/sim/renderer.h) with their exact target
// masks, downscaled to the network's input size and written as PNG pairs.
// Each simulator run draws its own variation (noise and map seeds, target
// size, camera standoff / height, scene texture, image noise, exposure) from
// the dataset seed, so a different seed gives a disjoint held-out set.

#include <cstdint>
#include <string>
#include <vector>

namespace vimot {
namespace segmentation {

struct SegmentationDataOptions {
  /// Simulator configs (config/sim_*.yaml) the runs are drawn from, in turn.
  std::vector<std::string> sim_configs;
  int runs{40};             // simulator runs (each with its own variation)
  int frames_per_run{20};   // instants per run, uniform over the run; every camera's image is kept
  uint64_t seed{1};         // variation of every run
  int width{320};           // px, written image and mask size
  int height{240};
};

/// Writes <out_dir>/img_NNNNN.png (8-bit grey) and mask_NNNNN.png (0 / 255)
/// pairs; returns the number of pairs. The directory must exist. Throws
/// std::invalid_argument for bad options, std::runtime_error when a file
/// cannot be written.
int write_segmentation_dataset(const SegmentationDataOptions& options, const std::string& out_dir);

}  // namespace segmentation
}  // namespace vimot

// vimot-segmentation-data: writes rendered training / test data for the
// segmentation network (common/segmentation/segmentation_data.h); run by
// scripts/train_segmenter.sh.
#include <cstdio>
#include <string>
#include <vector>

#include "common/process/arg_parser.h"
#include "common/segmentation/segmentation_data.h"

namespace {

using namespace vimot;

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-segmentation-data",
                 "Writes rendered grey images and their exact target masks (PNG pairs img_N.png,\n"
                 "mask_N.png, downscaled) for training and testing the segmentation network. Every\n"
                 "simulator run varies seeds, target size, camera standoff, textures, noise and\n"
                 "exposure, drawn from --seed (a different seed gives a held-out set).");
  args.add_option("configs", "FILES", "comma-separated simulator configs",
                  "config/sim_paper.yaml,config/sim_mono.yaml");
  args.add_option("out", "DIR", "output directory (must exist)");
  args.add_option("runs", "N", "simulator runs", "40");
  args.add_option("frames", "N", "instants per run (every camera's image kept)", "20");
  args.add_option("seed", "N", "variation seed", "1");
  args.add_option("size", "WxH", "written image size", "320x240");
  if (!args.parse(argc, argv)) return 0;
  if (!args.given("out")) throw ArgError("--out DIR is required");
  segmentation::SegmentationDataOptions o;
  o.sim_configs = split_comma_list(args.get("configs"));
  o.runs = static_cast<int>(args.get_int("runs"));
  o.frames_per_run = static_cast<int>(args.get_int("frames"));
  o.seed = static_cast<uint64_t>(args.get_int("seed"));
  if (std::sscanf(args.get("size").c_str(), "%dx%d", &o.width, &o.height) != 2) {
    throw ArgError("--size must be WxH, got " + args.get("size"));
  }
  const int n = segmentation::write_segmentation_dataset(o, args.get("out"));
  std::printf("vimot-segmentation-data: %d image/mask pairs in %s\n", n, args.get("out").c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-segmentation-data", argc, argv, run); }

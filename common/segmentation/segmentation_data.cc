#include "common/segmentation/segmentation_data.h"

#include <cstdio>
#include <random>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/config/config.h"
#include "common/sim/renderer.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"

namespace vimot {
namespace segmentation {
namespace {

// The run's variation around its scenario config: what a network must not
// learn by heart (where the target sits, its size and texture, the room's
// look, noise and brightness).
void vary(sim::SimConfig& c, std::mt19937_64& rng) {
  auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); };
  c.seed = rng();
  c.map_seed = rng();
  const double scale = uniform(0.5, 1.6);
  for (int k = 0; k < 3; ++k) c.target.size(k) *= scale * uniform(0.8, 1.25);
  c.paper.standoff = uniform(2.5, 10.0);
  c.paper.lateral_offset = uniform(-2.0, 2.0);
  c.paper.height = uniform(1.5, 4.5);
  c.paper.target_start_angle = uniform(0.0, 3.0);
  c.mono.camera_base.x() = uniform(-3.5, -1.5);
  c.mono.camera_base.z() = uniform(0.6, 2.2);
  c.render.scene_texture = uniform(0.0, 1.0) < 0.2 ? sim::SurfaceTexture::kCheckerboard : sim::SurfaceTexture::kPattern;
  // A whole number of texels dividing half the texture (SimConfig's check).
  c.render.checker_square = c.render.texel_size * (32 << std::uniform_int_distribution<int>(0, 3)(rng));
  c.render.noise_sigma = uniform(0.0, 6.0);
  c.render.exposure_amplitude = uniform(0.0, 0.5);
  c.render.exposure_frequency_hz = uniform(0.02, 0.2);
}

void write_png(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write '" + path + "'");
}

}  // namespace

int write_segmentation_dataset(const SegmentationDataOptions& o, const std::string& out_dir) {
  if (o.sim_configs.empty()) throw std::invalid_argument("segmentation data: no simulator config");
  if (o.runs < 1 || o.frames_per_run < 1 || o.width < 1 || o.height < 1) {
    throw std::invalid_argument("segmentation data: runs, frames_per_run, width and height must be >= 1");
  }
  std::vector<sim::SimConfig> bases;
  for (const std::string& file : o.sim_configs) bases.push_back(sim::from_config(Config::load_file(file)));
  std::mt19937_64 rng(o.seed);
  int written = 0;
  for (int run = 0; run < o.runs; ++run) {
    sim::SimConfig config = bases[run % bases.size()];
    vary(config, rng);
    const sim::Simulator sim(config);
    const sim::Renderer renderer(sim);
    std::uniform_int_distribution<int64_t> instant(sim.start_utime(), sim.end_utime());
    for (int f = 0; f < o.frames_per_run; ++f) {
      for (const sim::RenderedView& view : renderer.render(instant(rng))) {
        cv::Mat image, mask;
        cv::resize(view.image, image, cv::Size(o.width, o.height), 0, 0, cv::INTER_AREA);
        // Area-averaged, then a pixel is target when most of it was.
        cv::resize(view.mask, mask, cv::Size(o.width, o.height), 0, 0, cv::INTER_AREA);
        cv::threshold(mask, mask, 127, 255, cv::THRESH_BINARY);
        char stem[32];
        std::snprintf(stem, sizeof(stem), "%05d.png", written);
        write_png(out_dir + "/img_" + stem, image);
        write_png(out_dir + "/mask_" + stem, mask);
        ++written;
      }
    }
  }
  return written;
}

}  // namespace segmentation
}  // namespace vimot

// vimot-bench-target-faces: where on the target the front end's points lie.
// The rendered scenario's cam0 through the feature tracker (true box); every
// --every-th frame, each of the box's faces by the renderer's ray cast of
// its pixels: visible area, mean grey and grey std (texture contrast as
// rendered), FAST corners (non-max suppressed) at the tracker's ORB
// threshold, and the tracker's target features on it; features in the box
// whose ray hits the room count as "room". The object tracker's
// initialisation needs points off one face that live through its buffer
// (docs/object_tracker.md, "Initialisation"), so the features also present
// --lag frames earlier are counted per face as well.
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "bench/rendered_scenario_args.h"
#include "common/eval/pixel_frontend.h"
#include "common/process/arg_parser.h"

namespace {

using namespace vimot;

// Faces of the target box in its frame T: 0 +x, 1 -x, 2 +y, 3 -y, 4 +z
// (top), 5 -z; 6 the room seen inside the box.
constexpr int kFaces = 7;
constexpr int kRoom = 6;
const std::array<const char*, kFaces> kFaceNames{"+x", "-x", "+y", "-y", "top", "bottom", "room"};

struct FaceStats {
  double area{0}, grey_sum{0}, grey_sq{0}, fast{0}, features{0}, long_lived{0};
  int frames_visible{0};
};

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-target-faces",
                 "Per face of the rendered target (renderer ray cast): visible area, grey mean / std,\n"
                 "FAST corners at the ORB threshold, the feature tracker's target features on it and\n"
                 "those present --lag frames before; averaged over every --every-th frame.");
  add_rendered_scenario_options(args, "config/sim_mono.yaml", "config/feature_tracker_sim_mono.yaml", "20");
  args.add_option("every", "N", "frames between the measured frames", "10");
  args.add_option("lag", "N", "frames a feature must have lived (object tracker init_frames - 1)", "39");
  args.add_option("png", "PREFIX", "write each measured frame's box crop (x3) as PREFIX<k>.png");
  if (!args.parse(argc, argv)) return 0;
  const RenderedScenario scenario = rendered_scenario_from(args);
  const sim::Simulator sim(scenario.sim);
  eval::PixelFrontEnd front(sim, scenario.tracker);
  const int every = static_cast<int>(args.get_int("every"));
  const int lag = static_cast<int>(args.get_int("lag"));
  const Eigen::Vector3d half = 0.5 * scenario.sim.target.size;
  const cv::Ptr<cv::FastFeatureDetector> fast =
      cv::FastFeatureDetector::create(scenario.tracker.target.orb_fast_threshold, true);

  std::array<FaceStats, kFaces> stats{};
  std::vector<std::set<int64_t>> ids_per_frame;
  int measured = 0;
  const int64_t frames = sim.camera_frame_count();
  for (int64_t k = 0; k < frames; ++k) {
    const int64_t utime = sim.camera_utime(k);
    const CameraFrame frame = front.frame(utime);
    std::set<int64_t> ids;
    for (const FeatureObservation& f : frame.observations) {
      if (f.camera_id == 0 && f.is_target) ids.insert(f.feature_id);
    }
    ids_per_frame.push_back(ids);
    const sim::RenderedView& view = front.last_views().front();
    if (k % every != 0 || !view.visible) continue;
    const std::optional<sim::SplineState> target = sim.target_state(sim.sim_time(utime));
    if (!target) continue;
    ++measured;
    // The face a pixel sees: the box coordinate nearest its half-size.
    auto face_at = [&](const Eigen::Vector2d& px) {
      const sim::Renderer::SurfaceHit hit = front.renderer().surface_at(0, utime, px);
      if (!hit.on_target) return kRoom;
      const Eigen::Vector3d p_T = target->R_BtoG.transpose() * (hit.p_inG - target->p_BinG);
      int axis = 0;
      for (int a = 1; a < 3; ++a) {
        if (std::abs(p_T(a)) / half(a) > std::abs(p_T(axis)) / half(axis)) axis = a;
      }
      return 2 * axis + (p_T(axis) > 0.0 ? 0 : 1);
    };
    const cv::Rect box_rect(static_cast<int>(view.box(0)), static_cast<int>(view.box(1)),
                            static_cast<int>(view.box(2)) + 1, static_cast<int>(view.box(3)) + 1);
    const cv::Rect roi = box_rect & cv::Rect(0, 0, view.image.cols, view.image.rows);
    cv::Mat face_of(roi.size(), CV_8UC1, cv::Scalar(kRoom));
    std::array<double, kFaces> area{};
    for (int y = 0; y < roi.height; ++y) {
      for (int x = 0; x < roi.width; ++x) {
        if (view.mask.at<uint8_t>(roi.y + y, roi.x + x) == 0) continue;
        const int face = face_at(Eigen::Vector2d(roi.x + x, roi.y + y));
        face_of.at<uint8_t>(y, x) = static_cast<uint8_t>(face);
        const double g = view.image.at<uint8_t>(roi.y + y, roi.x + x);
        area[face] += 1.0;
        stats[face].grey_sum += g;
        stats[face].grey_sq += g * g;
      }
    }
    for (int f = 0; f < kFaces; ++f) {
      stats[f].area += area[f];
      if (area[f] > 0) ++stats[f].frames_visible;
    }
    std::vector<cv::KeyPoint> corners;
    fast->detect(view.image(roi), corners);
    for (const cv::KeyPoint& c : corners) {
      const int x = static_cast<int>(std::lround(c.pt.x)), y = static_cast<int>(std::lround(c.pt.y));
      if (x < roi.width && y < roi.height && view.mask.at<uint8_t>(roi.y + y, roi.x + x) != 0) {
        stats[face_of.at<uint8_t>(y, x)].fast += 1.0;
      }
    }
    const std::set<int64_t>* old =
        static_cast<int64_t>(ids_per_frame.size()) > lag ? &ids_per_frame[ids_per_frame.size() - 1 - lag] : nullptr;
    for (const FeatureObservation& f : frame.observations) {
      if (f.camera_id != 0 || !f.is_target) continue;
      const int face = face_at(f.pixel);
      stats[face].features += 1.0;
      if (old && old->count(f.feature_id)) stats[face].long_lived += 1.0;
    }
    if (args.given("png")) {
      cv::Mat crop;
      cv::resize(view.image(roi), crop, cv::Size(), 3.0, 3.0, cv::INTER_NEAREST);
      cv::imwrite(args.get("png") + std::to_string(k) + ".png", crop);
    }
  }
  std::printf("vimot-bench-target-faces: %s seed %s, %s s, %d frames measured (every %d), tracker %s\n\n",
              args.get("sim").c_str(), args.get("seed").c_str(), args.get("duration").c_str(), measured, every,
              args.get("tracker").c_str());
  std::printf("%-7s %8s %8s %6s %6s %10s %10s %12s\n", "face", "visible", "area px", "grey", "std", "FAST", "features",
              ("alive k-" + std::to_string(lag)).c_str());
  std::printf("%-7s %8s %8s %6s %6s %10s %10s %12s\n", "", "frames", "mean", "mean", "", "per frame", "per frame",
              "per frame");
  for (int f = 0; f < kFaces; ++f) {
    const FaceStats& s = stats[f];
    const double n = measured > 0 ? measured : 1;
    const double mean = s.area > 0 ? s.grey_sum / s.area : 0.0;
    const double sd = s.area > 0 ? std::sqrt(std::max(0.0, s.grey_sq / s.area - mean * mean)) : 0.0;
    std::printf("%-7s %8d %8.0f %6.1f %6.1f %10.1f %10.1f %12.1f\n", kFaceNames[f], s.frames_visible, s.area / n,
                f == kRoom ? 0.0 : mean, f == kRoom ? 0.0 : sd, s.fast / n, s.features / n, s.long_lived / n);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-target-faces", argc, argv, run); }

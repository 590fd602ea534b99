// vimot-bench-stack: the whole stack's time per stereo frame on one core,
// from the rendered images to the target estimate, with each stage's share:
// segmenter (the shipped network on both images), mask filter (both masks),
// feature tracker, and the joint VIO + target filter (its camera update, and
// its IMU propagation between frames) — the work of vimot-segmenter,
// vimot-mask-filter, vimot-feature-tracker and vimot-target-filter in
// sheriff_configs/sim_segmented.pmd, in-process and without LCM. The
// renderer (the simulator's camera) is timed apart, not in the stack.
// Thread CPU time (other jobs on a shared machine do not inflate it), one
// OpenCV thread. Also prints what the run computed: the filtered box against
// the true one, and the target in the IMU frame against the truth
// (vimot-target-eval's conventions, the filter's own target frame) next to
// the feature-level run of the same seed (the simulator's own tracks).
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <numeric>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/eval/evaluation_setup.h"
#include "common/eval/machine.h"
#include "common/eval/sim_runner.h"
#include "common/eval/target_eval.h"
#include "common/eval/target_frame.h"
#include "common/segmentation/blob.h"
#include "common/frontend/feature_tracker.h"
#include "common/process/arg_parser.h"
#include "common/segmentation/box_chain.h"
#include "common/sim/renderer.h"
#include "common/target/target_filter.h"
#include "common/time/utime.h"
#include "procs/eval/target_run.h"

namespace {

using namespace vimot;

struct Stage {
  const char* name;
  std::vector<double> ms;  // per stereo frame
  double mean() const { return std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(ms.size()); }
  double quantile(double q) const {
    std::vector<double> v = ms;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  }
};

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-stack",
                 "Whole-stack CPU time per stereo frame on one core, rendered paper scenario: segmenter\n"
                 "(onnx), mask filter, feature tracker, VIO + target filter (update and IMU propagation),\n"
                 "each stage's mean / median / p95 and share. Run from the source tree (or give the\n"
                 "config paths).");
  args.add_option("sim-config", "FILE", "simulator config", "config/sim_paper.yaml");
  args.add_option("vins-config", "FILE", "estimator config", "config/vins.yaml");
  args.add_option("target-config", "FILE", "target filter config", "config/target_filter.yaml");
  args.add_option("tracker-config", "FILE", "feature tracker config", "config/feature_tracker_segmented.yaml");
  args.add_option("segmenter", "FILE", "segmenter config (backend onnx)", "config/segmenter.yaml");
  args.add_option("mask-filter", "FILE", "mask filter config", "config/mask_filter.yaml");
  args.add_option("duration", "SECONDS", "simulated seconds", "10");
  args.add_option("seed", "S", "simulator seed", "1");
  if (!args.parse(argc, argv)) return 0;
  const long long seed = args.get_int("seed");
  if (seed < 0) throw ArgError("--seed must be >= 0");

  eval::EvaluationSetup setup =
      eval::load_evaluation_setup(args.get("sim-config"), args.get("vins-config"), args.get_double("duration"));
  setup.sim.seed = static_cast<uint64_t>(seed);
  setup.sim.ground_truth_events = true;
  const segmentation::BoxChainOptions chain =
      segmentation::BoxChainOptions::from_config_files(args.get("segmenter"), args.get("mask-filter"));
  if (chain.segmenter.backend != segmentation::SegmenterOptions::Backend::kOnnx) {
    throw ArgError("--segmenter: the bench times the network, backend must be onnx");
  }
  const frontend::FeatureTrackerOptions tracker_options =
      frontend::FeatureTrackerOptions::from_config(Config::load_file(args.get("tracker-config")), "tracker");
  target::TargetFilterOptions fo = eval::target_filter_options(Config::load_file(args.get("target-config")));

  cv::setNumThreads(1);
  sim::Simulator sim(setup.sim);
  if (sim.cameras().size() != 2) throw ArgError("--sim-config: a stereo scenario is needed");
  const sim::Renderer renderer(sim);
  segmentation::OnnxSegmenter segmenter(chain.segmenter.onnx);
  std::vector<segmentation::MaskFilter> filters(2, segmentation::MaskFilter(chain.filter));
  frontend::FeatureTracker tracker(tracker_options, sim.cameras());
  estimator::VioEstimator est(setup.vio);
  const uint64_t perturb_seed = estimator::perturb_seed_for_run(setup.sim.seed);
  const estimator::InitialEstimate x0 = estimator::initial_estimate(sim.initial_state(), setup.vio, perturb_seed);
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);
  fo.init_perturb_seed = perturb_seed;
  target::TargetFilter filter(est, fo);

  Stage render{"renderer (the simulator, not in the stack)", {}};
  Stage segment{"segmenter, 2 images", {}}, mask{"mask filter, 2 masks", {}}, track{"feature tracker", {}};
  Stage update{"VIO + target filter: camera update", {}}, propagate{"VIO + target filter: IMU propagation", {}};
  GroundTruth truth;
  bool target_seen = false;
  int32_t frame_start = 0;  // the filter's start whose frame X is
  eval::TargetFrameTransform X;
  eval::TrajectoryErrors target_errors;
  double iou_sum = 0.0;
  int64_t boxes_valid = 0, visible = 0;
  double frame_end = thread_cpu_ms();
  eval::play_simulator(
      sim, est,
      [&](const GroundTruth& gt) {
        truth = gt;
        filter.set_ground_truth(gt);
      },
      [&](const CameraFrame& simulated) {
        // Since the last frame: the IMU samples into the estimator (and the
        // simulator making them, a small part).
        double t = thread_cpu_ms();
        propagate.ms.push_back(t - frame_end);
        const auto lap = [&t](Stage& s) {
          const double now = thread_cpu_ms();
          s.ms.push_back(now - t);
          t = now;
        };
        const std::vector<sim::RenderedView> views = renderer.render(simulated.utime);
        lap(render);
        std::vector<cv::Mat> masks;
        for (const sim::RenderedView& v : views) masks.push_back(segmenter.segment(v.image));
        lap(segment);
        std::optional<frontend::Box> boxes[2];
        segmentation::BoxEstimate estimates[2];
        for (std::size_t c = 0; c < 2; ++c) {
          estimates[c] = filters[c].process(simulated.utime, masks[c]);
          if (const auto b = segmentation::tracker_box(estimates[c])) {
            boxes[c] = frontend::Box{(*b)(0), (*b)(1), (*b)(2), (*b)(3)};
          }
        }
        lap(mask);
        const CameraFrame tracked = tracker.track(simulated.utime, views[0].image, views[1].image, boxes[0], boxes[1]);
        lap(track);
        const estimator::FrameStatus st = est.feed_camera(tracked);
        lap(update);
        // Accuracy (not timed).
        for (std::size_t c = 0; c < 2; ++c) {
          if (!views[c].visible) continue;
          ++visible;
          if (!estimates[c].filtered_valid) continue;
          ++boxes_valid;
          iou_sum += segmentation::box_iou(estimates[c].filtered_box, views[c].box);
        }
        for (const FeatureObservation& o : tracked.observations) target_seen = target_seen || o.is_target;
        if (filter.initialized() && truth.utime == simulated.utime && truth.has_target && target_seen &&
            st == estimator::FrameStatus::kProcessed) {
          const target::TargetValue x = filter.value();
          if (filter.starts() != frame_start) X = eval::target_frame_transform(truth, x.q_RtoT, x.p_TinR);
          frame_start = filter.starts();
          const eval::TargetInImu ti = eval::true_target_in_imu(eval::in_target_frame(truth, X));
          const target::Matrix12d P = filter.covariance();
          target_errors.add(eval::compute_error(simulated.utime, ti.q_ItoT, ti.p_TinI, x.q_RtoT, x.p_TinR,
                                                P.block<3, 3>(0, 0), P.block<3, 3>(3, 3)));
        }
        frame_end = thread_cpu_ms();
        return st != estimator::FrameStatus::kDiverged;
      });

  const eval::MachineInfo machine = eval::machine_info();
  std::printf("machine: %s, %d hardware threads; OpenCV threads: %d\n", machine.cpu_model.c_str(), machine.nproc,
              cv::getNumThreads());
  std::printf("scenario %s, seed %lld, %zu stereo frames (%dx%d), target filter %s\n", args.get("sim-config").c_str(),
              seed, segment.ms.size(), sim.cameras()[0].width, sim.cameras()[0].height,
              filter.initialized() ? "initialised" : "NOT initialised");
  std::vector<double> total(segment.ms.size(), 0.0);
  const std::vector<const Stage*> stack{&segment, &mask, &track, &update, &propagate};
  for (const Stage* s : stack) {
    for (std::size_t k = 0; k < total.size(); ++k) total[k] += s->ms[k];
  }
  const Stage whole{"whole stack", total};
  std::printf("%-42s %9s %9s %9s %7s\n", "CPU ms per stereo frame", "mean", "median", "p95", "share");
  for (const Stage* s : stack) {
    std::printf("%-42s %9.2f %9.2f %9.2f %6.1f%%\n", s->name, s->mean(), s->quantile(0.5), s->quantile(0.95),
                100.0 * s->mean() / whole.mean());
  }
  std::printf("%-42s %9.2f %9.2f %9.2f %6.1f%%\n", whole.name, whole.mean(), whole.quantile(0.5), whole.quantile(0.95),
              100.0);
  std::printf("%-42s %9.2f %9.2f %9.2f\n", render.name, render.mean(), render.quantile(0.5), render.quantile(0.95));

  const eval::ErrorSummary e = target_errors.summary();
  std::printf("box: valid filtered box in %lld of %lld camera images with the target, mean IoU with the true box %.3f\n",
              static_cast<long long>(boxes_valid), static_cast<long long>(visible),
              boxes_valid > 0 ? iou_sum / static_cast<double>(boxes_valid) : 0.0);
  std::printf("target in IMU, this run (pixels, segmenter, mask filter): position RMSE %.4f m, orientation RMSE "
              "%.3f deg, %lld frames\n",
              e.rmse_position_m, e.rmse_orientation_deg, static_cast<long long>(e.count));
  const eval::TargetRunResult ref = eval::run_target_on_sim(setup.sim, setup.vio, fo, perturb_seed, nullptr, false);
  std::printf("target in IMU, feature level (same seed and start): position RMSE %.4f m, orientation RMSE %.3f deg; "
              "ratio %.2f / %.2f\n",
              ref.target_in_imu.rmse_position_m, ref.target_in_imu.rmse_orientation_deg,
              e.rmse_position_m / ref.target_in_imu.rmse_position_m,
              e.rmse_orientation_deg / ref.target_in_imu.rmse_orientation_deg);
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-stack", argc, argv, run); }

// The whole chain from pixels to the target, LCM-free (the cores of
// sheriff_configs/sim_segmented.pmd): rendered paper scenario → segmenter
// backend truth with the corruption of config/segmenter_truth.yaml
// (dropouts of 6 frames, missed frames, false blobs, boundary noise) → mask
// filter → feature tracker → VIO + target filter started from its own
// features. The box must be kept through the dropouts and re-acquired on
// the target after them, and the filter keep its target estimate.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/eval/evaluation_setup.h"
#include "common/eval/metrics.h"
#include "common/eval/pixel_frontend.h"
#include "common/eval/sim_runner.h"
#include "common/eval/target_eval.h"
#include "common/eval/target_frame.h"
#include "common/segmentation/blob.h"
#include "common/segmentation/box_chain.h"
#include "common/target/target_filter.h"

using namespace vimot;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

// One camera's frame as the test sees it.
struct CamFrame {
  bool visible{false};    // the true target is in the image
  bool in_dropout{false}; // the corruptor removed the target (a dropout, not a single miss)
  segmentation::BoxEstimate box;
  Eigen::Vector4d true_box{Eigen::Vector4d::Zero()};
};

struct ChainRun {
  std::vector<std::vector<CamFrame>> cams{2};
  std::vector<bool> target_estimate;           // per frame: the filter has a target
  eval::ErrorSummary target_in_imu;
  segmentation::TruthCorruptionCounts corruption, twin;
  bool diverged{false};
};

// The paper scenario from pixels through VIO + target filter, the box from
// `chain`, with vimot-target-eval's error conventions
// (run_target_on_sim) in the filter's own target frame.
ChainRun run_chain(const eval::EvaluationSetup& setup, const target::TargetFilterOptions& fo,
                   const frontend::FeatureTrackerOptions& tracker, uint64_t perturb_seed,
                   const segmentation::BoxChainOptions& chain) {
  sim::SimConfig cfg = setup.sim;
  cfg.ground_truth_events = true;
  sim::Simulator sim(cfg);
  eval::PixelFrontEnd front(sim, tracker, chain);
  // The same corruption again (deterministic per seed and camera) tells the
  // test which frames were dropped out, which the chain's output cannot.
  segmentation::TruthCorruptor twin(chain.segmenter.truth);

  estimator::VioEstimator est(setup.vio);
  const estimator::InitialEstimate x0 = estimator::initial_estimate(sim.initial_state(), setup.vio, perturb_seed);
  est.initialize(x0.value, sim.initial_state().utime, x0.P0);
  target::TargetFilter filter(est, fo);

  ChainRun r;
  GroundTruth truth;
  bool target_seen = false, frame_known = false;
  eval::TargetFrameTransform X;
  eval::TrajectoryErrors errors;
  eval::play_simulator(
      sim, est, [&](const GroundTruth& gt) { truth = gt; },
      [&](const CameraFrame& frame) {
        for (std::size_t c = 0; c < 2; ++c) {
          const sim::RenderedView& v = front.last_views()[c];
          const int64_t before = twin.counts().dropout_frames;
          twin.corrupt(static_cast<int>(c), v.mask);
          r.cams[c].push_back({v.visible, twin.counts().dropout_frames > before, front.last_boxes()[c], v.box});
        }
        for (const FeatureObservation& o : frame.observations) target_seen = target_seen || o.is_target;
        if (est.feed_camera(frame) == estimator::FrameStatus::kDiverged) {
          r.diverged = true;
          return false;
        }
        r.target_estimate.push_back(filter.initialized());
        if (!filter.initialized() || truth.utime != frame.utime || !truth.has_target || !target_seen) return true;
        const target::TargetValue x = filter.value();
        if (!frame_known) X = eval::target_frame_transform(truth, x.q_RtoT, x.p_TinR);
        frame_known = true;
        const eval::TargetInImu t = eval::true_target_in_imu(eval::in_target_frame(truth, X));
        const target::Matrix12d P = filter.covariance();
        errors.add(eval::compute_error(frame.utime, t.q_ItoT, t.p_TinI, x.q_RtoT, x.p_TinR, P.block<3, 3>(0, 0),
                                       P.block<3, 3>(3, 3)));
        return true;
      },
      &front);
  r.target_in_imu = errors.summary();
  if (const auto* c = front.box_chain()->corruption_counts()) r.corruption = *c;
  r.twin = twin.counts();
  return r;
}

}  // namespace

TEST_CASE("segmented chain: corrupted true masks with dropouts and false blobs, the target is kept and re-acquired") {
  const double duration_s = 15.0;
  eval::EvaluationSetup setup = eval::load_evaluation_setup(source_path("config/sim_paper.yaml"),
                                                            source_path("config/vins.yaml"), duration_s);
  setup.sim.seed = 1;
  const uint64_t perturb_seed = estimator::perturb_seed_for_run(setup.sim.seed);
  const Config target_cfg = Config::load_file(source_path("config/target_filter.yaml"));
  target::TargetFilterOptions fo = eval::target_filter_options(target_cfg);
  REQUIRE(fo.representation == target::TargetRepresentation::kLocal);  // value() is the target in the IMU frame
  REQUIRE(fo.init_mode == target::TargetInitMode::kFeatures);          // no ground truth in the chain
  fo.init_perturb_seed = perturb_seed;

  segmentation::BoxChainOptions chain;
  chain.segmenter = segmentation::SegmenterOptions::from_config(Config::load_file(source_path("config/segmenter_truth.yaml")));
  REQUIRE(chain.segmenter.backend == segmentation::SegmenterOptions::Backend::kTruth);
  REQUIRE(chain.segmenter.truth.dropout_frames >= 5);
  REQUIRE(chain.segmenter.truth.false_blob_rate > 0.0);
  chain.filter = segmentation::MaskFilterOptions::from_config(Config::load_file(source_path("config/mask_filter.yaml")),
                                                              "filter");
  const frontend::FeatureTrackerOptions tracker = frontend::FeatureTrackerOptions::from_config(
      Config::load_file(source_path("config/feature_tracker_segmented.yaml")), "tracker");

  const ChainRun r = run_chain(setup, fo, tracker, perturb_seed, chain);
  REQUIRE_FALSE(r.diverged);
  const std::size_t n = r.target_estimate.size();
  REQUIRE(n > 100);

  // The corruption happened: dropouts of >= 5 frames with the target in view, in both cameras.
  const segmentation::TruthCorruptionCounts& cc = r.corruption;
  INFO("dropouts " << cc.dropouts << " (" << cc.dropout_frames << " frames), missed " << cc.missed
                   << ", false blobs " << cc.false_blobs << " in " << n << " stereo frames");
  REQUIRE(cc.dropouts == r.twin.dropouts);  // the twin saw what the chain did
  REQUIRE(cc.false_blobs > static_cast<int64_t>(n));

  // Box kept: a valid filtered box in every frame with the target in view,
  // except past max_coast_s of consecutive dropped frames (back-to-back
  // dropouts join), where the filter rightly drops the box.
  const int max_coast_frames = static_cast<int>(std::floor(chain.filter.kalman.max_coast_s * setup.sim.camera.rate_hz));
  int reacquisitions = 0;
  for (std::size_t c = 0; c < 2; ++c) {
    int dropout_run = 0, dropouts_seen = 0;
    for (std::size_t k = 1; k < n; ++k) {
      const CamFrame& f = r.cams[c][k];
      INFO("camera " << c << " frame " << k);
      dropout_run = f.in_dropout ? dropout_run + 1 : 0;
      if (f.visible && dropout_run < max_coast_frames) CHECK(f.box.filtered_valid);
      // Re-acquired: within 3 frames of a dropout's end (a single missed frame
      // may follow) a detection is fused again and the box is on the target.
      if (!r.cams[c][k - 1].in_dropout || f.in_dropout || !f.visible) continue;
      ++dropouts_seen;
      bool reacquired = false;
      for (std::size_t j = k; j < std::min(n, k + 3) && !reacquired; ++j) {
        const CamFrame& g = r.cams[c][j];
        reacquired = g.box.filtered_valid && g.box.frames_since_raw == 0 &&
                     segmentation::box_iou(g.box.filtered_box, g.true_box) >= 0.5;
      }
      CHECK(reacquired);
      reacquisitions += reacquired ? 1 : 0;
    }
    CHECK(dropouts_seen >= 1);
  }

  // Target kept: once started (from its own features), the filter has a
  // target in every frame, dropouts and false blobs included.
  std::size_t first = 0;
  while (first < n && !r.target_estimate[first]) ++first;
  REQUIRE(first < n / 2);
  for (std::size_t k = first; k < n; ++k) CHECK(r.target_estimate[k]);
  const eval::ErrorSummary& s = r.target_in_imu;
  REQUIRE(s.count > 0);
  // The accuracy this costs is measured, not asserted (docs/segmented_pipeline.md):
  // the issue asks only that the target be kept and re-acquired here.
  WARN("corrupted masks: target in IMU position RMSE " << s.rmse_position_m << " m, orientation "
       << s.rmse_orientation_deg << " deg over " << s.count << " frames; " << reacquisitions << " re-acquisitions");
}

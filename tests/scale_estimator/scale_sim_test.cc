// Scale estimator on the simulator's mono scenario (config/sim_mono.yaml)
// and its degenerate presets C1-C4 (config/sim_mono_c*.yaml), with the
// thresholds of config/scale_estimator.yaml. The observations come from the
// simulator's truth at every camera frame: the camera pose from the true
// IMU pose and cam0's extrinsics, the up-to-scale object pose is the true
// object pose in C with its position divided by s_true, the object's depth
// at the first frame (the tracker's unit, scale paper Fig. 5). Noise:
//   VINS camera pose: 1 mm per axis, 0.05 deg per axis, white per frame;
//   object pose: 1 px equivalent, white per frame: lateral d / f (the
//   position error that moves the object's projection by 1 px at depth d),
//   depth 3 d / f (monocular depth from the object's apparent size is worse
//   conditioned by about d / L ~ 3 for the 0.4 m box at 1.5-3 m).
// White noise is the pessimistic case for finite differences (a bundle
// adjustment's errors are smooth in time).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/math/quat.h"
#include "common/object/scale_estimator.h"
#include "common/sim/sim_config.h"
#include "common/sim/simulator.h"
#include "procs/scale_estimator/scale_node.h"

using namespace vimot;
using namespace vimot::scale;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

struct TruthRun {
  double s_true{0.0};
  std::vector<ScaleObservation> observations;
};

sim::SimConfig load(const std::string& sim_yaml) {
  return sim::from_config(Config::load_file(source_path(sim_yaml)));
}

TruthRun truth_observations(const sim::SimConfig& config, uint64_t noise_seed) {
  const sim::Simulator sim(config);
  const CameraCalibration& cam0 = sim.cameras().at(0);
  const double f = 0.5 * (cam0.intrinsics(0) + cam0.intrinsics(1));
  std::mt19937_64 rng(noise_seed);
  std::normal_distribution<double> n01;
  auto noise3 = [&](double sigma) -> Eigen::Vector3d { return Eigen::Vector3d(n01(rng), n01(rng), n01(rng)) * sigma; };
  const double kCamPosSigma = 1e-3;                 // m
  const double kCamAttSigma = 0.05 * M_PI / 180.0;   // rad
  const double kPixelSigma = 1.0;                   // px

  TruthRun run;
  for (int64_t k = 0; k < sim.camera_frame_count(); ++k) {
    const int64_t utime = sim.camera_utime(k);
    const double t = sim.sim_time(utime);
    const sim::SplineState imu = sim.robot_state(t);
    const sim::SplineState object = *sim.target_state(t);
    const CameraPoseInWorld cam = camera_pose_in_world(rot_to_quat(imu.R_BtoG.transpose()), imu.p_BinG, cam0);
    const Eigen::Matrix3d R_OtoC = cam.R_CtoG.transpose() * object.R_BtoG;
    const Eigen::Vector3d p_OinC = cam.R_CtoG.transpose() * (object.p_BinG - cam.p_CinG);
    if (k == 0) run.s_true = p_OinC.z();
    const double d = p_OinC.norm();
    const Eigen::Vector3d obj_noise(n01(rng) * d * kPixelSigma / f, n01(rng) * d * kPixelSigma / f,
                                    n01(rng) * 3.0 * d * kPixelSigma / f);
    const Eigen::Matrix3d R_CtoG_est = cam.R_CtoG * exp_so3(noise3(kCamAttSigma));
    run.observations.push_back(ScaleObservation::from_rotations(
        utime, R_CtoG_est, cam.p_CinG + noise3(kCamPosSigma), R_OtoC, (p_OinC + obj_noise) / run.s_true));
  }
  return run;
}

ScaleEstimatorOptions shipped_options() {
  return ScaleEstimatorOptions::from_config(Config::load_file(source_path("config/scale_estimator.yaml")));
}

// The paper's estimator: the shipped thresholds and window, no band-pass.
ScaleEstimatorOptions paper_options() {
  ScaleEstimatorOptions o = shipped_options();
  o.motion_lowpass_s = 0.0;
  o.motion_highpass_s = 0.0;
  return o;
}

struct Summary {
  int estimates{0};
  int accepted{0};
  int failed[5]{0, 0, 0, 0, 0};
  int condition_not_ok[3]{0, 0, 0};  // per sub-condition, not only the first failing
  ScaleResult last;
  double max_rel_error{0.0};  // over all estimates
  std::vector<double> accepted_rel_errors;
};

Summary run_estimator(const TruthRun& run, const ScaleEstimatorOptions& options) {
  ScaleEstimator est(options);
  Summary s;
  for (const ScaleObservation& o : run.observations) {
    REQUIRE(is_added(est.add(o)));
    const ScaleResult r = est.update();
    if (r.status == ScaleStatus::kInsufficientData) continue;
    ++s.estimates;
    ++s.failed[r.failed_condition];
    for (int k = 0; k < 3; ++k) s.condition_not_ok[k] += !r.condition_ok[k];
    const double error = std::abs(r.scale / run.s_true - 1.0);
    s.max_rel_error = std::max(s.max_rel_error, error);
    if (r.accepted) {
      ++s.accepted;
      s.accepted_rel_errors.push_back(error);
    }
    s.last = r;
  }
  return s;
}

std::string describe(const Summary& s, double s_true) {
  std::ostringstream os;
  os << "s_true " << s_true << ": " << s.estimates << " estimates, " << s.accepted << " accepted, max |s*/s - 1| "
     << s.max_rel_error << ", failed (i) " << s.failed[1] << " (ii) " << s.failed[2] << " (iii) "
     << s.failed[3] << " (s<=0) " << s.failed[4] << "; (iii) not ok " << s.condition_not_ok[2] << "; last: s* " << s.last.scale << " f " << s.last.f_value
     << " f_rel " << s.last.f_relative << " sumC2 " << s.last.condition[1] << " sumD2 " << s.last.condition[2];
  return os.str();
}

}  // namespace

// The normal case the estimator is made for, config/sim_mono.yaml as
// shipped: a hand-held camera shaking (0.37-1.73 Hz) faster than the object
// moves (0.05, 0.10 Hz), so camera and object velocities decorrelate within
// the 40 s window. Accepted by the paper's estimator and by the shipped
// band-pass one; the band-pass takes out the object's band, where the
// finite window leaves a covariance with the camera (Eq. 15), so its worst
// accepted error is smaller on every seed.
TEST_CASE("scale_sim: sim_mono.yaml, hand-held excitation, accepted near s_true", "[scale][sim]") {
  const sim::SimConfig config = load("config/sim_mono.yaml");
  for (uint64_t seed : {1, 2, 3}) {
    const TruthRun run = truth_observations(config, seed);
    double max_error[2] = {0.0, 0.0};
    int i = 0;
    for (const ScaleEstimatorOptions& options : {paper_options(), shipped_options()}) {
      const Summary s = run_estimator(run, options);
      INFO("seed " << seed << (i == 0 ? ", paper: " : ", band-pass: ") << describe(s, run.s_true));
      CHECK(s.accepted >= 0.9 * s.estimates);
      std::vector<double> errors = s.accepted_rel_errors;
      REQUIRE(!errors.empty());
      std::sort(errors.begin(), errors.end());
      const double median = errors[errors.size() / 2];
      INFO("accepted |s*/s - 1|: median " << median << ", max " << errors.back());
      CHECK(median < 0.02);
      CHECK(errors.back() < 0.05);
      max_error[i++] = errors.back();
    }
    CHECK(max_error[1] < max_error[0]);
  }
}

// The camera's translation of the earlier sim_mono.yaml, with slow terms
// (0.07-0.17 Hz) within 0.01-0.02 Hz of the object's figure-eight (0.05,
// 0.10 Hz): over any window shorter than 50-100 s their velocities covary
// (Eq. 15: O = Cov(m_o, m_c) is not small). The paper's estimator is off by
// 5-40 % (noise-free truth gives the same s*: it is the motion, not the
// noise) and (i) rightly rejects it: f(s*) >= 6e-5 against epsilon_t1 =
// 1e-5. The band-pass (0.3 s / 2.5 s boxes) keeps only the camera's faster
// terms (0.31-0.53 Hz), where the object hardly moves: accepted, within 2 %.
TEST_CASE("scale_sim: camera motion correlated with the object's in the slow band", "[scale][sim]") {
  sim::SimConfig config = load("config/sim_mono.yaml");
  config.mono.camera_translation = {
      {Eigen::Vector3d(0.35, 0.45, 0.15), Eigen::Vector3d(0.11, 0.07, 0.17), Eigen::Vector3d(0.0, 0.5, 1.0)},
      {Eigen::Vector3d(0.08, 0.10, 0.06), Eigen::Vector3d(0.43, 0.31, 0.53), Eigen::Vector3d(1.0, 2.0, 0.3)}};
  const TruthRun run = truth_observations(config, 1);
  const ScaleEstimatorOptions paper_opts = paper_options();
  const Summary paper = run_estimator(run, paper_opts);
  INFO("paper: " << describe(paper, run.s_true));
  // One estimate per frame from the one that fills the window on (none before).
  CHECK(paper.estimates == static_cast<int>(run.observations.size()) - paper_opts.min_observations + 1);
  CHECK(paper.accepted == 0);
  CHECK(paper.failed[1] == paper.estimates);
  CHECK(paper.max_rel_error > 0.1);
  const Summary band = run_estimator(run, shipped_options());
  INFO("band-pass: " << describe(band, run.s_true));
  CHECK(band.accepted == band.estimates);
  CHECK(band.max_rel_error < 0.02);
}

// Table I of the scale paper, with the paper's estimator (no band-pass):
// each degenerate case rejected by the sub-condition the table names. The
// shipped band-pass rejects them all too, by (ii): their camera moves only
// in the slow band (with the object, or not at all), so within the band the
// camera is not excited.
namespace {
void check_rejected_by_shipped(const TruthRun& run) {
  const Summary s = run_estimator(run, shipped_options());
  INFO("band-pass: " << describe(s, run.s_true));
  CHECK(s.estimates > 0);
  CHECK(s.accepted == 0);
  CHECK(s.failed[2] == s.estimates);
}
}  // namespace

TEST_CASE("scale_sim: C1 camera translates as the object, rejected by (i)", "[scale][sim]") {
  const TruthRun run = truth_observations(load("config/sim_mono_c1.yaml"), 1);
  const Summary s = run_estimator(run, paper_options());
  INFO(describe(s, run.s_true));
  CHECK(s.accepted == 0);
  CHECK(s.failed[1] == s.estimates);
  // m_d = (v_O - v_C) / s = 0 up to noise: (iii) fails as well.
  CHECK(!s.last.condition_ok[2]);
  check_rejected_by_shipped(run);
}

TEST_CASE("scale_sim: C2 static camera and C3 constant velocity, rejected by (ii)", "[scale][sim]") {
  for (const char* preset : {"config/sim_mono_c2.yaml", "config/sim_mono_c3.yaml"}) {
    const TruthRun run = truth_observations(load(preset), 1);
    const Summary s = run_estimator(run, paper_options());
    INFO(preset << ": " << describe(s, run.s_true));
    CHECK(s.accepted == 0);
    CHECK(s.failed[2] == s.estimates);
    check_rejected_by_shipped(run);
  }
}

// The paper's C4: the camera rides rigidly on the object, which only
// translates (object_heading: fixed), so p_bar is constant, R_CtoG is
// constant and m_d = d/dt(R_CtoG p_bar) = 0 up to noise: (iii) fails in
// every window, as Table I says. failed_condition reports (i), the first
// failing sub-condition: with D ~ 0, f(s*) = sum C^2 sin^2(D, C) ~ sum C^2,
// and (ii) holds (sum C^2 >= rho_t1 > epsilon_t1), so (i) cannot pass
// either. Only a camera rotation aligned with its translation (the yawing
// platform of scale_scenarios_test.cc) makes (iii) the sole failure.
TEST_CASE("scale_sim: C4 object static in the camera frame, (iii) fails", "[scale][sim]") {
  const TruthRun run = truth_observations(load("config/sim_mono_c4.yaml"), 1);
  const Summary s = run_estimator(run, paper_options());
  INFO(describe(s, run.s_true));
  CHECK(s.accepted == 0);
  CHECK(s.condition_not_ok[2] == s.estimates);
  CHECK(s.condition_not_ok[1] == 0);
  CHECK(s.failed[1] == s.estimates);
  check_rejected_by_shipped(run);
}

// config/vins.yaml: load_vio_options gives the estimator the simulator's
// model (the same options the end-to-end test copied from the Simulator),
// writes the VioOptions defaults out, and reports errors by key.
#include <catch2/catch.hpp>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <unistd.h>

#include "common/config/config.h"
#include "common/estimator/vins_config.h"
#include "common/eval/evaluation_setup.h"
#include "common/sim/simulator.h"

using namespace vimot;
using namespace vimot::eval;
using estimator::VinsStartOptions;
using estimator::load_start_options;
using estimator::load_vio_options;
using estimator::VioOptions;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

bool same_cameras(const std::vector<CameraCalibration>& a, const std::vector<CameraCalibration>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].width != b[i].width || a[i].height != b[i].height || a[i].intrinsics != b[i].intrinsics ||
        a[i].distortion != b[i].distortion || a[i].R_ItoC != b[i].R_ItoC || a[i].p_IinC != b[i].p_IinC) {
      return false;
    }
  }
  return true;
}

// Every option the estimator reads, compared exactly.
void check_same_options(const VioOptions& a, const VioOptions& b) {
  CHECK(a.state.max_clones == b.state.max_clones);
  CHECK(a.state.max_slam == b.state.max_slam);
  CHECK(a.state.use_fej == b.state.use_fej);
  CHECK(a.state.slam_representation == b.state.slam_representation);
  CHECK(a.propagator.noise.sigma_w == b.propagator.noise.sigma_w);
  CHECK(a.propagator.noise.sigma_a == b.propagator.noise.sigma_a);
  CHECK(a.propagator.noise.sigma_wb == b.propagator.noise.sigma_wb);
  CHECK(a.propagator.noise.sigma_ab == b.propagator.noise.sigma_ab);
  CHECK(a.propagator.gravity_magnitude == b.propagator.gravity_magnitude);
  CHECK(a.propagator.max_gap_s == b.propagator.max_gap_s);
  CHECK(a.propagator.buffer_s == b.propagator.buffer_s);
  CHECK(a.msckf.chi2_multiplier == b.msckf.chi2_multiplier);
  CHECK(a.msckf.max_features_per_update == b.msckf.max_features_per_update);
  CHECK(a.msckf.min_clone_times == b.msckf.min_clone_times);
  CHECK(a.slam.chi2_multiplier == b.slam.chi2_multiplier);
  CHECK(a.slam.max_init_per_frame == b.slam.max_init_per_frame);
  CHECK(a.slam.max_chi2_failures == b.slam.max_chi2_failures);
  CHECK(a.triangulation.min_depth == b.triangulation.min_depth);
  CHECK(a.triangulation.max_depth == b.triangulation.max_depth);
  CHECK(a.triangulation.max_condition == b.triangulation.max_condition);
  CHECK(a.triangulation.max_iterations == b.triangulation.max_iterations);
  CHECK(a.static_init.window_s == b.static_init.window_s);
  CHECK(a.static_init.max_accel_std == b.static_init.max_accel_std);
  CHECK(a.static_init.gravity_magnitude == b.static_init.gravity_magnitude);
  CHECK(a.init_sigmas.theta_rp == b.init_sigmas.theta_rp);
  CHECK(a.init_sigmas.theta_yaw == b.init_sigmas.theta_yaw);
  CHECK(a.init_sigmas.p == b.init_sigmas.p);
  CHECK(a.init_sigmas.v == b.init_sigmas.v);
  CHECK(a.init_sigmas.bg == b.init_sigmas.bg);
  CHECK(a.init_sigmas.ba == b.init_sigmas.ba);
  CHECK(a.divergence.max_position_correction_m == b.divergence.max_position_correction_m);
  CHECK(a.divergence.max_velocity_mps == b.divergence.max_velocity_mps);
  CHECK(a.init_mode == b.init_mode);
  CHECK(a.use_stereo == b.use_stereo);
  CHECK(a.sigma_px == b.sigma_px);
  CHECK(same_cameras(a.cameras, b.cameras));
}

// A file in a fresh temp directory, removed at the end.
class TempDir {
 public:
  TempDir() {
    char name[] = "/tmp/vimot_eval_cfg_XXXXXX";
    REQUIRE(mkdtemp(name) != nullptr);
    path_ = name;
  }
  ~TempDir() { std::system(("rm -rf '" + path_ + "'").c_str()); }
  std::string write(const std::string& file, const std::string& text) const {
    const std::string p = path_ + "/" + file;
    std::ofstream(p) << text;
    return p;
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace

TEST_CASE("config/vins.yaml configures the estimator as copied from the paper simulator", "[eval][config]") {
  const VioOptions loaded = load_vio_options(source_path("config/vins.yaml"));

  // The end-to-end test's way: the file's tuning, then IMU noise, gravity,
  // cameras and pixel noise copied from the Simulator: nothing may change.
  const sim::Simulator s(sim::from_config(Config::load_file(source_path("config/sim_paper.yaml"))));
  VioOptions copied = loaded;
  copied.cameras = s.cameras();
  copied.sigma_px = s.config().camera.pixel_noise;
  copied.propagator.noise.sigma_w = s.imu_config().gyroscope_noise_density;
  copied.propagator.noise.sigma_a = s.imu_config().accelerometer_noise_density;
  copied.propagator.noise.sigma_wb = s.imu_config().gyroscope_random_walk;
  copied.propagator.noise.sigma_ab = s.imu_config().accelerometer_random_walk;
  copied.propagator.gravity_magnitude = s.imu_config().gravity;
  check_same_options(loaded, copied);
  CHECK(model_mismatches(loaded, s.config()).empty());
  check_same_options(loaded, options_matching_sim(loaded, s.config()));
}

TEST_CASE("config/vins.yaml: tuned values read, the rest are the VioOptions defaults", "[eval][config]") {
  const VioOptions loaded = load_vio_options(source_path("config/vins.yaml"));
  VioOptions expected = VioOptions::from_config(Config::load_file(source_path("config/euroc_stereo.yaml")));
  // The values the file sets away from the defaults (see its header).
  expected.msckf.max_features_per_update = 100;
  expected.triangulation.max_condition = 1e6;
  expected.init_sigmas.theta_rp = 0.001;
  expected.init_sigmas.theta_yaw = 0.001;
  expected.init_sigmas.p = 0.001;
  expected.init_sigmas.v = 0.001;
  expected.init_sigmas.bg = 0.0001;
  expected.init_sigmas.ba = 0.001;
  check_same_options(loaded, expected);

  const VinsStartOptions start = load_start_options(source_path("config/vins.yaml"));
  CHECK(start.mode == estimator::InitMode::kGroundTruth);
  CHECK(start.perturb_seed == 1);
  const Config cfg = Config::load_file(source_path("config/vins.yaml"));
  CHECK(cfg.get<std::string>("channels.imu") == "IMU");
  CHECK(cfg.get<std::string>("channels.features") == "FEATURES");
  CHECK(cfg.get<std::string>("channels.ground_truth") == "GROUND_TRUTH");
  CHECK(cfg.get<std::string>("channels.state") == "VINS_STATE");
}

TEST_CASE("The trajectory scenario has the same estimator model", "[eval][config]") {
  const char* saved = std::getenv("VIMOT_DATA_DIR");
  const std::string saved_value = saved ? saved : "";
  setenv("VIMOT_DATA_DIR", "/some/data", 1);  // from_config only expands the path
  const sim::SimConfig traj = sim::from_config(Config::load_file(source_path("config/sim_trajectory.yaml")));
  if (saved) {
    setenv("VIMOT_DATA_DIR", saved_value.c_str(), 1);
  } else {
    unsetenv("VIMOT_DATA_DIR");
  }
  CHECK(model_mismatches(load_vio_options(source_path("config/vins.yaml")), traj).empty());
}

TEST_CASE("model_mismatches names what differs", "[eval][config]") {
  const sim::SimConfig paper = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  VioOptions o = load_vio_options(source_path("config/vins.yaml"));
  o.sigma_px = 1.5;
  o.propagator.noise.sigma_a = 0.004;
  const std::vector<std::string> m = model_mismatches(o, paper);
  REQUIRE(m.size() == 2);
  CHECK_THAT(m[0], Catch::Contains("accelerometer noise density"));
  CHECK_THAT(m[1], Catch::Contains("pixel noise: estimator 1.5 px, simulator 1 px"));
  o = load_vio_options(source_path("config/vins.yaml"));
  o.use_stereo = false;
  CHECK_THAT(model_mismatches(o, paper).at(0), Catch::Contains("cameras: estimator uses 1, simulator has 2"));
}

TEST_CASE("vins config: calibration relative to the file, keys checked", "[eval][config]") {
  TempDir dir;
  std::ifstream calib(source_path("config/euroc_stereo.yaml"));
  std::stringstream text;
  text << calib.rdbuf();
  dir.write("my_calib.yaml", text.str());

  const std::string ok = dir.write("vins.yaml",
                                   "calibration_file: my_calib.yaml\n"
                                   "init: {mode: static, perturb_seed: 5}\n"
                                   "estimator:\n  num_clones: 7\n  init: {sigma_yaw: 0.2}\n");
  const VioOptions o = load_vio_options(ok);
  CHECK(o.state.max_clones == 7);
  CHECK(o.init_sigmas.theta_yaw == 0.2);
  CHECK(o.init_mode == estimator::InitMode::kStatic);
  CHECK(o.cameras.size() == 2);
  CHECK(load_start_options(ok).perturb_seed == 5);

  const std::string missing = dir.write("missing.yaml", "calibration_file: nowhere.yaml\n");
  CHECK_THROWS_AS(load_vio_options(missing), ConfigError);

  const std::string bad_key = dir.write("bad.yaml", "calibration_file: my_calib.yaml\nestimator: {num_clones: 1}\n");
  CHECK_THROWS_WITH(load_vio_options(bad_key), Catch::Contains("num_clones"));

  const std::string bad_mode = dir.write("mode.yaml", "calibration_file: my_calib.yaml\ninit: {mode: magic}\n");
  CHECK_THROWS_WITH(load_vio_options(bad_mode), Catch::Contains("init.mode"));
  const std::string nested_mode =
      dir.write("nested.yaml", "calibration_file: my_calib.yaml\nestimator: {init: {mode: static}}\n");
  CHECK_THROWS_WITH(load_vio_options(nested_mode), Catch::Contains("estimator.init.mode"));
  const std::string bad_seed = dir.write("seed.yaml", "init: {perturb_seed: -3}\n");
  CHECK_THROWS_WITH(load_start_options(bad_seed), Catch::Contains("init.perturb_seed"));
}

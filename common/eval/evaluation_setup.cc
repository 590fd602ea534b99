#include "common/eval/evaluation_setup.h"

#include <sstream>
#include <stdexcept>

#include "common/config/config.h"
#include "common/estimator/vins_config.h"

namespace vimot {
namespace eval {

namespace {

std::string num(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

bool same_camera(const CameraCalibration& a, const CameraCalibration& b) {
  return a.width == b.width && a.height == b.height && a.intrinsics == b.intrinsics &&
         a.distortion_model == b.distortion_model && a.distortion == b.distortion && a.R_ItoC == b.R_ItoC && a.p_IinC == b.p_IinC;
}

}  // namespace

std::vector<std::string> model_mismatches(const estimator::VioOptions& o, const sim::SimConfig& s) {
  std::vector<std::string> out;
  auto cmp = [&out](const std::string& what, double est, double sim, const std::string& unit) {
    if (est != sim) out.push_back(what + ": estimator " + num(est) + unit + ", simulator " + num(sim) + unit);
  };
  const estimator::ImuNoise& n = o.propagator.noise;
  if (s.imu.noise) {
    cmp("gyroscope noise density", n.sigma_w, s.imu.gyroscope_noise_density, " rad/s/sqrt(Hz)");
    cmp("accelerometer noise density", n.sigma_a, s.imu.accelerometer_noise_density, " m/s^2/sqrt(Hz)");
    cmp("gyroscope random walk", n.sigma_wb, s.imu.gyroscope_random_walk, " rad/s^2/sqrt(Hz)");
    cmp("accelerometer random walk", n.sigma_ab, s.imu.accelerometer_random_walk, " m/s^3/sqrt(Hz)");
  } else {
    out.push_back("IMU noise: off in the simulator, the estimator assumes noise");
  }
  cmp("gravity", o.propagator.gravity_magnitude, s.imu.gravity, " m/s^2");
  cmp("pixel noise", o.sigma_px, s.camera.pixel_noise, " px");
  const std::size_t used = o.use_stereo ? o.cameras.size() : std::min<std::size_t>(1, o.cameras.size());
  const std::size_t simulated = s.camera.calibrations.size();
  if (used != simulated) {
    out.push_back("cameras: estimator uses " + std::to_string(used) + ", simulator has " +
                  std::to_string(simulated));
  }
  for (std::size_t i = 0; i < std::min(o.cameras.size(), simulated); ++i) {
    if (!same_camera(o.cameras[i], s.camera.calibrations[i])) {
      out.push_back("cam" + std::to_string(i) + ": calibrations differ");
    }
  }
  return out;
}

estimator::VioOptions options_matching_sim(estimator::VioOptions o, const sim::SimConfig& s) {
  o.cameras = s.camera.calibrations;
  o.use_stereo = o.cameras.size() >= 2;
  o.sigma_px = s.camera.pixel_noise;
  o.propagator.noise.sigma_w = s.imu.gyroscope_noise_density;
  o.propagator.noise.sigma_a = s.imu.accelerometer_noise_density;
  o.propagator.noise.sigma_wb = s.imu.gyroscope_random_walk;
  o.propagator.noise.sigma_ab = s.imu.accelerometer_random_walk;
  o.propagator.gravity_magnitude = s.imu.gravity;
  o.static_init.gravity_magnitude = s.imu.gravity;
  return o;
}

EvaluationSetup load_evaluation_setup(const std::string& sim_yaml, const std::string& vins_yaml,
                                      std::optional<double> duration_s) {
  EvaluationSetup setup;
  setup.sim = sim::from_config(Config::load_file(sim_yaml));
  if (duration_s) {
    if (!(*duration_s > 0.0)) {
      throw std::invalid_argument("duration must be > 0 s, got " + std::to_string(*duration_s));
    }
    setup.sim.duration = *duration_s;
  }
  setup.vio = estimator::load_vio_options(vins_yaml);
  setup.model_mismatches = model_mismatches(setup.vio, setup.sim);
  return setup;
}

}  // namespace eval
}  // namespace vimot

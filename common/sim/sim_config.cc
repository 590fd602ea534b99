#include "common/sim/sim_config.h"

#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/config/config.h"

namespace vimot {
namespace sim {

namespace {

std::string fmt(double v) {
  std::ostringstream ss;
  ss.precision(10);
  ss << v;
  return ss.str();
}

std::string fmt(const Eigen::Vector3d& v) { return "[" + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + "]"; }

// ---- validation (shared by validate() and from_config()) ------------------

bool power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Whole number of `unit`s in `length` (to 1e-6 relative).
bool whole_multiple(double length, double unit) {
  const double n = length / unit;
  return std::round(n) >= 1.0 && std::abs(n - std::round(n)) < 1e-6 * n;
}

// The render section's problems, as problem().
std::string render_problem(const SimConfig& c) {
  const RenderConfig& r = c.render;
  std::ostringstream err;
  if (!(r.texel_size > 0.0) || !std::isfinite(r.texel_size)) {
    err << "key 'render.texel_size' must be > 0, got " << fmt(r.texel_size);
  } else if (!power_of_two(r.texture_size) || r.texture_size < 16 || r.texture_size > 8192) {
    err << "key 'render.texture_size' must be a power of two in [16, 8192], got " << r.texture_size;
  } else if (!power_of_two(r.target_texture_size) || r.target_texture_size < 16 || r.target_texture_size > 4096) {
    err << "key 'render.target_texture_size' must be a power of two in [16, 4096], got " << r.target_texture_size;
  } else if (!(r.checker_square > 0.0) || !std::isfinite(r.checker_square)) {
    err << "key 'render.checker_square' must be > 0, got " << fmt(r.checker_square);
  } else if (!(r.noise_sigma >= 0.0) || !std::isfinite(r.noise_sigma)) {
    err << "key 'render.noise_sigma' must be >= 0, got " << fmt(r.noise_sigma);
  } else if (!(r.exposure_amplitude >= 0.0 && r.exposure_amplitude <= 2.0)) {
    err << "key 'render.exposure_amplitude' must be in [0, 2] (log gain), got " << fmt(r.exposure_amplitude);
  } else if (!(r.exposure_frequency_hz >= 0.0) || !std::isfinite(r.exposure_frequency_hz)) {
    err << "key 'render.exposure_frequency_hz' must be >= 0, got " << fmt(r.exposure_frequency_hz);
  } else if (!(r.target_ambient >= 0.0 && r.target_ambient <= 1.0)) {
    err << "key 'render.target_ambient' must be in [0, 1], got " << fmt(r.target_ambient);
  } else if (r.scene_texture == SurfaceTexture::kCheckerboard &&
             !(whole_multiple(r.checker_square, r.texel_size) &&
               r.texture_size % (2 * static_cast<int>(std::lround(r.checker_square / r.texel_size))) == 0)) {
    // Square edges on texel boundaries and a whole number of square pairs
    // per texture period, or the corners would not be where the config says.
    err << "key 'render.checker_square' must be a whole number of texels (render.texel_size " << fmt(r.texel_size)
        << " m) dividing half of render.texture_size " << r.texture_size << ", got " << fmt(r.checker_square);
  } else if (r.target_texture == SurfaceTexture::kCheckerboard &&
             !whole_multiple(r.checker_square, c.target.size.maxCoeff() / r.target_texture_size)) {
    err << "key 'render.checker_square' must be a whole number of target texels (longest target edge "
        << fmt(c.target.size.maxCoeff()) << " m / render.target_texture_size " << r.target_texture_size
        << "), got " << fmt(r.checker_square);
  }
  return err.str();
}

// paper.rc_car (issue 15): "" or its first problem.
std::string rc_car_problem(const RcCarConfig& rc) {
  std::ostringstream err;
  auto range = [&err](const char* key, double lo, double hi, bool zero_ok) {
    const bool ok = std::isfinite(lo) && std::isfinite(hi) && (zero_ok ? lo >= 0.0 : lo > 0.0) && hi >= lo;
    if (!ok && err.tellp() == 0) {
      err << "key 'paper.rc_car." << key << "' must be [min, max] with " << (zero_ok ? "0 <= " : "0 < ")
          << "min <= max, got [" << fmt(lo) << ", " << fmt(hi) << "]";
    }
  };
  range("speed_range", rc.speed_min, rc.speed_max, false);
  range("hold_range", rc.hold_min, rc.hold_max, false);
  range("stop_range", rc.stop_min, rc.stop_max, true);
  if (err.tellp() != 0) return err.str();
  if (!(rc.max_acceleration > 0.0) || !std::isfinite(rc.max_acceleration)) {
    err << "key 'paper.rc_car.max_acceleration' must be > 0, got " << fmt(rc.max_acceleration);
  } else if (!(rc.stop_probability >= 0.0 && rc.stop_probability < 1.0)) {
    err << "key 'paper.rc_car.stop_probability' must be in [0, 1), got " << fmt(rc.stop_probability);
  } else if (!(rc.heading_spacing > 0.0) || !std::isfinite(rc.heading_spacing)) {
    err << "key 'paper.rc_car.heading_spacing' must be > 0, got " << fmt(rc.heading_spacing);
  } else if (!(rc.heading_deviation >= 0.0 && rc.heading_deviation < 0.5 * M_PI)) {
    err << "key 'paper.rc_car.heading_deviation' must be in [0, π/2), got " << fmt(rc.heading_deviation);
  }
  return err.str();
}

// Returns "" or the first problem as "key 'a.b' must ..., got ...".
std::string problem(const SimConfig& c) {
  std::ostringstream err;
  auto positive = [&err](const char* key, double v) {
    if (!(v > 0.0) || !std::isfinite(v)) err << "key '" << key << "' must be > 0, got " << fmt(v);
    return err.tellp() == 0;
  };
  auto non_negative = [&err](const char* key, double v) {
    if (!(v >= 0.0) || !std::isfinite(v)) err << "key '" << key << "' must be >= 0, got " << fmt(v);
    return err.tellp() == 0;
  };
  auto count = [&err](const char* key, int v) {
    if (v < 0) err << "key '" << key << "' must be >= 0, got " << v;
    return err.tellp() == 0;
  };
  auto finite3 = [&err](const char* key, const Eigen::Vector3d& v) {
    if (!v.allFinite()) err << "key '" << key << "' must be finite, got " << fmt(v);
    return err.tellp() == 0;
  };
  const bool ok =
      non_negative("duration", c.duration) && positive("imu.rate_hz", c.imu.rate_hz) &&
      non_negative("imu.gyroscope_noise_density", c.imu.gyroscope_noise_density) &&
      non_negative("imu.gyroscope_random_walk", c.imu.gyroscope_random_walk) &&
      non_negative("imu.accelerometer_noise_density", c.imu.accelerometer_noise_density) &&
      non_negative("imu.accelerometer_random_walk", c.imu.accelerometer_random_walk) &&
      finite3("imu.initial_gyro_bias", c.imu.initial_gyro_bias) &&
      finite3("imu.initial_accel_bias", c.imu.initial_accel_bias) && non_negative("imu.gravity", c.imu.gravity) &&
      positive("camera.rate_hz", c.camera.rate_hz) && non_negative("camera.pixel_noise", c.camera.pixel_noise) &&
      positive("camera.min_depth", c.camera.min_depth) && positive("camera.max_range", c.camera.max_range) &&
      non_negative("camera.max_depth", c.camera.max_depth) &&
      non_negative("camera.border", c.camera.border) && count("camera.keep_per_camera", c.camera.keep_per_camera) &&
      positive("camera.spawn_depth_min", c.camera.spawn_depth_min) &&
      count("map.floor_points", c.map.floor_points) && count("map.wall_points", c.map.wall_points) &&
      non_negative("map.wall_height", c.map.wall_height) && non_negative("map.margin", c.map.margin) &&
      count("target.points_per_face", c.target.points_per_face) &&
      non_negative("target.edge_margin", c.target.edge_margin) && finite3("target.size", c.target.size);
  if (!ok) return err.str();
  if (c.camera.calibrations.empty() || c.camera.calibrations.size() > 2) {
    err << "key 'camera.mode' must give 1 (mono) or 2 (stereo) cameras, got " << c.camera.calibrations.size();
  } else if (c.imu.rate_hz > 1e6 || c.camera.rate_hz > 1e6) {
    err << "key 'imu.rate_hz' / 'camera.rate_hz' must be <= 1e6 (one sample per µs), got " << fmt(c.imu.rate_hz)
        << " / " << fmt(c.camera.rate_hz);
  } else if (!(c.camera.track_loss_probability >= 0.0 && c.camera.track_loss_probability <= 1.0)) {
    err << "key 'camera.track_loss_probability' must be in [0, 1], got " << fmt(c.camera.track_loss_probability);
  } else if (!(c.camera.spawn_depth_max >= c.camera.spawn_depth_min)) {
    err << "key 'camera.spawn_depth' must be [min, max] with max >= min, got [" << fmt(c.camera.spawn_depth_min)
        << ", " << fmt(c.camera.spawn_depth_max) << "]";
  } else if (c.camera.keep_per_camera > 0 && 2.0 * c.camera.spawn_depth_max > c.camera.max_range) {
    err << "key 'camera.max_range' must be >= 2 x the spawn depth max (spawned points in the image corners "
           "must stay in range), got "
        << fmt(c.camera.max_range) << " with spawn depth max " << fmt(c.camera.spawn_depth_max);
  } else if (c.camera.keep_per_camera > 0 && c.camera.max_depth > 0.0 &&
             c.camera.max_depth < c.camera.spawn_depth_max) {
    err << "key 'camera.max_depth' must be 0 or >= the spawn depth max, got " << fmt(c.camera.max_depth)
        << " with spawn depth max " << fmt(c.camera.spawn_depth_max);
  } else if (!(c.target.size.minCoeff() > 2.0 * c.target.edge_margin)) {
    err << "key 'target.size' must exceed 2 x target.edge_margin along every axis, got " << fmt(c.target.size)
        << " with margin " << fmt(c.target.edge_margin);
  } else if (!(c.target.min_view_cos >= 0.0 && c.target.min_view_cos < 1.0)) {
    err << "key 'target.min_view_cos' must be in [0, 1), got " << fmt(c.target.min_view_cos);
  }
  if (err.tellp() != 0) return err.str();
  const std::string render = render_problem(c);
  if (!render.empty()) return render;
  switch (c.scenario) {
    case Scenario::kPaper:
      if (positive("paper.radius", c.paper.radius) && positive("paper.speed", c.paper.speed) &&
          positive("paper.spline_dt", c.paper.spline_dt) && positive("paper.height", c.paper.height)) {
        if (!(c.paper.standoff > 0.0 || std::abs(c.paper.lateral_offset) > 0.0)) {
          err << "keys 'paper.standoff' / 'paper.lateral_offset' must place the camera away from the target, got "
              << fmt(c.paper.standoff) << " / " << fmt(c.paper.lateral_offset);
        }
      }
      if (err.tellp() == 0 && c.paper.target_motion == TargetMotion::kRcCar) err << rc_car_problem(c.paper.rc_car);
      break;
    case Scenario::kTrajectory:
      if (c.trajectory.file.empty()) err << "key 'trajectory.file' must name a trajectory file";
      else non_negative("trajectory.spline_dt", c.trajectory.spline_dt);
      non_negative("trajectory.start_distance", c.trajectory.start_distance);
      break;
    case Scenario::kMono:
      if (positive("mono.duration", c.mono.duration) && positive("mono.spline_dt", c.mono.spline_dt)) {
        if (!(c.mono.room_max.array() > c.mono.room_min.array()).all()) {
          err << "key 'mono.room_max' must exceed mono.room_min";
        }
      }
      break;
  }
  return err.str();
}

// ---- YAML reading ---------------------------------------------------------

class Reader {
 public:
  explicit Reader(const Config& root) : root_(root) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw ConfigError("config '" + root_.source() + "': key '" + key + "' " + what);
  }

  // Rejects keys of the map at `section` ("" = top level) not in `allowed`.
  void only_keys(const std::string& section, const std::vector<std::string>& allowed) const {
    root_.check_keys(section, allowed);
  }

  template <typename T>
  void read(const std::string& key, T* out) const {
    if (root_.has(key)) *out = root_.get<T>(key);
  }
  void read_vec3(const std::string& key, Eigen::Vector3d* out) const {
    if (root_.has(key)) *out = root_.get_vec<3>(key);
  }
  void read_vec2(const std::string& key, Eigen::Vector2d* out) const {
    if (root_.has(key)) *out = root_.get_vec<2>(key);
  }
  void read_sinusoid(const std::string& key, Sinusoid3* out) const {
    only_keys(key, {"amplitude", "frequency_hz", "phase"});
    read_vec3(key + ".amplitude", &out->amplitude);
    read_vec3(key + ".frequency_hz", &out->frequency_hz);
    read_vec3(key + ".phase", &out->phase);
  }
  // A map of named sinusoids (in file order) replacing the defaults.
  void read_sinusoids(const std::string& key, std::vector<Sinusoid3>* out) const {
    if (!root_.has(key)) return;
    out->clear();
    for (const std::string& name : root_.sub(key).keys()) {
      Sinusoid3 s;
      read_sinusoid(key + "." + name, &s);
      out->push_back(s);
    }
  }
  const Config& root() const { return root_; }

 private:
  const Config& root_;
};

// Expands ${NAME} from the environment; an unset variable is an error.
std::string expand_env(const Reader& r, const std::string& key, const std::string& value) {
  std::string out;
  std::size_t pos = 0;
  while (pos < value.size()) {
    const std::size_t open = value.find("${", pos);
    if (open == std::string::npos) {
      out += value.substr(pos);
      break;
    }
    const std::size_t close = value.find('}', open);
    if (close == std::string::npos) r.fail(key, "has an unterminated '${' in '" + value + "'");
    out += value.substr(pos, open - pos);
    const std::string name = value.substr(open + 2, close - open - 2);
    const char* env = std::getenv(name.c_str());
    if (env == nullptr || *env == '\0') {
      r.fail(key, "uses ${" + name + "}, which is not set in the environment ('" + value + "')");
    }
    out += env;
    pos = close + 1;
  }
  return out;
}

// paper.target_motion and paper.rc_car (issue 15).
void read_target_motion(const Config& config, const Reader& r, PaperScenarioConfig* paper) {
  try {
    if (config.has("paper.target_motion")) {
      paper->target_motion = target_motion_from_string(config.get<std::string>("paper.target_motion"));
    }
  } catch (const std::invalid_argument& e) {
    r.fail("paper.target_motion", std::string("is invalid: ") + e.what());
  }
  r.only_keys("paper.rc_car", {"speed_range", "max_acceleration", "hold_range", "stop_probability", "stop_range",
                               "heading_spacing", "heading_deviation"});
  RcCarConfig& rc = paper->rc_car;
  auto read_range = [&](const std::string& key, double* lo, double* hi) {
    if (!config.has(key)) return;
    const Eigen::Vector2d v = config.get_vec<2>(key);
    *lo = v.x();
    *hi = v.y();
  };
  read_range("paper.rc_car.speed_range", &rc.speed_min, &rc.speed_max);
  r.read("paper.rc_car.max_acceleration", &rc.max_acceleration);
  read_range("paper.rc_car.hold_range", &rc.hold_min, &rc.hold_max);
  r.read("paper.rc_car.stop_probability", &rc.stop_probability);
  read_range("paper.rc_car.stop_range", &rc.stop_min, &rc.stop_max);
  r.read("paper.rc_car.heading_spacing", &rc.heading_spacing);
  r.read("paper.rc_car.heading_deviation", &rc.heading_deviation);
}

}  // namespace

uint64_t derive_seed(uint64_t seed, uint64_t stream) {
  // splitmix64 of the seed, then of the stream-mixed state.
  auto mix = [](uint64_t z) {
    z += 0x9E3779B97F4A7C15ULL;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
  };
  return mix(mix(seed) ^ (stream * 0xD1B54A32D192ED03ULL));
}

Scenario scenario_from_string(const std::string& name) {
  if (name == "paper") return Scenario::kPaper;
  if (name == "trajectory") return Scenario::kTrajectory;
  if (name == "mono") return Scenario::kMono;
  throw std::invalid_argument("unknown scenario '" + name + "' (expected paper, trajectory or mono)");
}

std::string to_string(Scenario scenario) {
  switch (scenario) {
    case Scenario::kPaper:
      return "paper";
    case Scenario::kTrajectory:
      return "trajectory";
    case Scenario::kMono:
      return "mono";
  }
  return "?";
}

TargetMotion target_motion_from_string(const std::string& name) {
  if (name == "semicircle") return TargetMotion::kSemicircle;
  if (name == "rc_car") return TargetMotion::kRcCar;
  throw std::invalid_argument("unknown target motion '" + name + "' (expected semicircle or rc_car)");
}

CameraAnchor camera_anchor_from_string(const std::string& name) {
  if (name == "world") return CameraAnchor::kWorld;
  if (name == "object_translation") return CameraAnchor::kObjectTranslation;
  if (name == "object_pose") return CameraAnchor::kObjectPose;
  throw std::invalid_argument("unknown camera anchor '" + name + "' (expected world, object_translation or object_pose)");
}

CameraPointing camera_pointing_from_string(const std::string& name) {
  if (name == "look_at_object") return CameraPointing::kLookAtObject;
  if (name == "fixed") return CameraPointing::kFixed;
  throw std::invalid_argument("unknown camera pointing '" + name + "' (expected look_at_object or fixed)");
}

ObjectHeading object_heading_from_string(const std::string& name) {
  if (name == "along_velocity") return ObjectHeading::kAlongVelocity;
  if (name == "fixed") return ObjectHeading::kFixed;
  throw std::invalid_argument("unknown object heading '" + name + "' (expected along_velocity or fixed)");
}

SurfaceTexture surface_texture_from_string(const std::string& name) {
  if (name == "pattern") return SurfaceTexture::kPattern;
  if (name == "checkerboard") return SurfaceTexture::kCheckerboard;
  throw std::invalid_argument("unknown surface texture '" + name + "' (expected pattern or checkerboard)");
}

void validate(const SimConfig& config) {
  const std::string p = problem(config);
  if (!p.empty()) throw std::invalid_argument("SimConfig: " + p);
}

SimConfig from_config(const Config& config) {
  const Reader r(config);
  SimConfig c;
  r.only_keys("", {"scenario", "seed", "map_seed", "start_utime", "duration", "ground_truth_events",
                   "calibration_file", "cameras", "imu", "camera", "map", "target", "paper", "trajectory", "mono",
                   "render", "comment",
                   // Read by the process that runs the simulator (drivers/sim), not here.
                   "channels"});
  const std::string scenario = config.get<std::string>("scenario");
  try {
    c.scenario = scenario_from_string(scenario);
  } catch (const std::invalid_argument& e) {
    r.fail("scenario", std::string("is invalid: ") + e.what());
  }
  int64_t seed = static_cast<int64_t>(c.seed), map_seed = static_cast<int64_t>(c.map_seed);
  r.read("seed", &seed);
  r.read("map_seed", &map_seed);
  c.seed = static_cast<uint64_t>(seed);
  c.map_seed = static_cast<uint64_t>(map_seed);
  r.read("start_utime", &c.start_utime);
  r.read("duration", &c.duration);
  r.read("ground_truth_events", &c.ground_truth_events);

  // Calibration: cameras (ASL layout) and IMU noise densities live in the
  // calibration file if one is named, else in this file.
  const Config calib = config.has("calibration_file")
                           ? Config::load_file(config.resolve_path(config.get<std::string>("calibration_file")))
                           : config;

  r.only_keys("camera", {"mode", "rate_hz", "pixel_noise", "min_depth", "max_range", "max_depth", "border",
                         "track_loss_probability", "keep_per_camera", "spawn_depth"});
  const std::string mode = config.get_or<std::string>("camera.mode", "stereo");
  if (mode != "stereo" && mode != "mono") r.fail("camera.mode", "must be 'stereo' or 'mono', got '" + mode + "'");
  c.camera.calibrations.push_back(camera_from_config(calib.sub("cameras.cam0")));
  if (mode == "stereo") c.camera.calibrations.push_back(camera_from_config(calib.sub("cameras.cam1")));
  r.read("camera.rate_hz", &c.camera.rate_hz);
  r.read("camera.pixel_noise", &c.camera.pixel_noise);
  r.read("camera.min_depth", &c.camera.min_depth);
  r.read("camera.max_range", &c.camera.max_range);
  r.read("camera.max_depth", &c.camera.max_depth);
  r.read("camera.border", &c.camera.border);
  r.read("camera.track_loss_probability", &c.camera.track_loss_probability);
  r.read("camera.keep_per_camera", &c.camera.keep_per_camera);
  if (config.has("camera.spawn_depth")) {
    const Eigen::Vector2d d = config.get_vec<2>("camera.spawn_depth");
    c.camera.spawn_depth_min = d.x();
    c.camera.spawn_depth_max = d.y();
  }

  r.only_keys("imu", {"rate_hz", "noise", "gyroscope_noise_density", "gyroscope_random_walk",
                      "accelerometer_noise_density", "accelerometer_random_walk", "initial_gyro_bias",
                      "initial_accel_bias", "gravity", "comment"});
  r.read("imu.rate_hz", &c.imu.rate_hz);
  r.read("imu.noise", &c.imu.noise);
  auto noise_value = [&](const std::string& key, double* out) {
    *out = config.has(key) ? config.get<double>(key) : calib.get<double>(key);
  };
  noise_value("imu.gyroscope_noise_density", &c.imu.gyroscope_noise_density);
  noise_value("imu.gyroscope_random_walk", &c.imu.gyroscope_random_walk);
  noise_value("imu.accelerometer_noise_density", &c.imu.accelerometer_noise_density);
  noise_value("imu.accelerometer_random_walk", &c.imu.accelerometer_random_walk);
  r.read_vec3("imu.initial_gyro_bias", &c.imu.initial_gyro_bias);
  r.read_vec3("imu.initial_accel_bias", &c.imu.initial_accel_bias);
  r.read("imu.gravity", &c.imu.gravity);

  r.only_keys("map", {"floor_points", "wall_points", "wall_height", "margin"});
  r.read("map.floor_points", &c.map.floor_points);
  r.read("map.wall_points", &c.map.wall_points);
  r.read("map.wall_height", &c.map.wall_height);
  r.read("map.margin", &c.map.margin);

  r.only_keys("target", {"enabled", "size", "base_height", "points_per_face", "edge_margin", "min_view_cos"});
  r.read("target.enabled", &c.target.enabled);
  if (config.has("target.size")) {
    // A number (cube edge) or [x, y, z].
    double edge = 0.0;
    try {
      edge = config.get<double>("target.size");
      c.target.size = Eigen::Vector3d::Constant(edge);
    } catch (const ConfigError&) {
      c.target.size = config.get_vec<3>("target.size");
    }
  }
  r.read("target.base_height", &c.target.base_height);
  r.read("target.points_per_face", &c.target.points_per_face);
  r.read("target.edge_margin", &c.target.edge_margin);
  r.read("target.min_view_cos", &c.target.min_view_cos);

  r.only_keys("paper", {"radius", "speed", "target_start_angle", "standoff", "lateral_offset", "height",
                        "oscillation", "spline_dt", "target_motion", "rc_car"});
  r.read("paper.radius", &c.paper.radius);
  r.read("paper.speed", &c.paper.speed);
  r.read("paper.target_start_angle", &c.paper.target_start_angle);
  r.read("paper.standoff", &c.paper.standoff);
  r.read("paper.lateral_offset", &c.paper.lateral_offset);
  r.read("paper.height", &c.paper.height);
  if (config.has("paper.oscillation")) r.read_sinusoid("paper.oscillation", &c.paper.oscillation);
  r.read("paper.spline_dt", &c.paper.spline_dt);
  read_target_motion(config, r, &c.paper);

  r.only_keys("trajectory", {"file", "spline_dt", "start_distance"});
  if (config.has("trajectory.file")) {
    const std::string raw = config.get<std::string>("trajectory.file");
    // A path from an environment variable is taken as given; a literal
    // relative path is relative to the config file.
    c.trajectory.file = raw.rfind("${", 0) == 0 ? expand_env(r, "trajectory.file", raw)
                                                : config.resolve_path(expand_env(r, "trajectory.file", raw));
  }
  r.read("trajectory.spline_dt", &c.trajectory.spline_dt);
  r.read("trajectory.start_distance", &c.trajectory.start_distance);

  r.only_keys("mono", {"duration", "object_center", "object_amplitude", "object_frequency_hz", "object_phase",
                       "object_heading", "camera_anchor", "camera_pointing", "camera_base", "camera_velocity",
                       "camera_translation", "camera_wobble", "room_min", "room_max", "spline_dt"});
  r.read("mono.duration", &c.mono.duration);
  r.read_vec2("mono.object_center", &c.mono.object_center);
  r.read_vec2("mono.object_amplitude", &c.mono.object_amplitude);
  r.read_vec2("mono.object_frequency_hz", &c.mono.object_frequency_hz);
  r.read_vec2("mono.object_phase", &c.mono.object_phase);
  try {
    if (config.has("mono.object_heading")) {
      c.mono.object_heading = object_heading_from_string(config.get<std::string>("mono.object_heading"));
    }
  } catch (const std::invalid_argument& e) {
    r.fail("mono.object_heading", std::string("is invalid: ") + e.what());
  }
  try {
    if (config.has("mono.camera_anchor")) {
      c.mono.anchor = camera_anchor_from_string(config.get<std::string>("mono.camera_anchor"));
    }
  } catch (const std::invalid_argument& e) {
    r.fail("mono.camera_anchor", std::string("is invalid: ") + e.what());
  }
  try {
    if (config.has("mono.camera_pointing")) {
      c.mono.pointing = camera_pointing_from_string(config.get<std::string>("mono.camera_pointing"));
    }
  } catch (const std::invalid_argument& e) {
    r.fail("mono.camera_pointing", std::string("is invalid: ") + e.what());
  }
  r.read_vec3("mono.camera_base", &c.mono.camera_base);
  r.read_vec3("mono.camera_velocity", &c.mono.camera_velocity);
  r.read_sinusoids("mono.camera_translation", &c.mono.camera_translation);
  r.read_sinusoids("mono.camera_wobble", &c.mono.camera_wobble);
  r.read_vec2("mono.room_min", &c.mono.room_min);
  r.read_vec2("mono.room_max", &c.mono.room_max);
  r.read("mono.spline_dt", &c.mono.spline_dt);

  r.only_keys("render", {"texel_size", "texture_size", "target_texture_size", "scene_texture", "target_texture",
                         "checker_square", "noise_sigma", "exposure_amplitude", "exposure_frequency_hz",
                         "target_ambient"});
  r.read("render.texel_size", &c.render.texel_size);
  r.read("render.texture_size", &c.render.texture_size);
  r.read("render.target_texture_size", &c.render.target_texture_size);
  for (const auto& [key, out] : {std::pair<const char*, SurfaceTexture*>{"render.scene_texture", &c.render.scene_texture},
                                 {"render.target_texture", &c.render.target_texture}}) {
    try {
      if (config.has(key)) *out = surface_texture_from_string(config.get<std::string>(key));
    } catch (const std::invalid_argument& e) {
      r.fail(key, std::string("is invalid: ") + e.what());
    }
  }
  r.read("render.checker_square", &c.render.checker_square);
  r.read("render.noise_sigma", &c.render.noise_sigma);
  r.read("render.exposure_amplitude", &c.render.exposure_amplitude);
  r.read("render.target_ambient", &c.render.target_ambient);
  r.read("render.exposure_frequency_hz", &c.render.exposure_frequency_hz);

  const std::string p = problem(c);
  if (!p.empty()) throw ConfigError("config '" + config.source() + "': " + p);
  return c;
}

}  // namespace sim
}  // namespace vimot

#pragma once
// Every parameter of the simulator, with defaults, and its YAML reader.
//
// Units are SI throughout (m, s, rad, Hz); pixel quantities say "px".
// Frames: G world (z up, gravity along -z), I IMU, C camera, T target.
// See docs/simulator.md for the scenarios and the YAML layout.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "common/camera/camera_model.h"

namespace vimot {

class Config;

namespace sim {

enum class Scenario {
  kPaper,       // UAV follows a planar target on a semicircle (Schmidt-EKF paper, Sec. IV)
  kTrajectory,  // robot pose from a TUM trajectory file, no target
  kMono,        // hand-held mono camera + IMU, a moving box (scale paper)
};

/// Parses "paper" / "trajectory" / "mono"; throws std::invalid_argument.
Scenario scenario_from_string(const std::string& name);
std::string to_string(Scenario scenario);

struct ImuSimConfig {
  double rate_hz{200.0};
  /// false: measurements are the true signals plus the constant initial
  /// biases (no white noise, no bias random walk).
  bool noise{true};
  double gyroscope_noise_density{1.6968e-04};      // rad/s/√Hz
  double gyroscope_random_walk{1.9393e-05};        // rad/s²/√Hz
  double accelerometer_noise_density{2.0e-3};      // m/s²/√Hz
  double accelerometer_random_walk{3.0e-3};        // m/s³/√Hz
  Eigen::Vector3d initial_gyro_bias{Eigen::Vector3d::Zero()};   // rad/s, in I
  Eigen::Vector3d initial_accel_bias{Eigen::Vector3d::Zero()};  // m/s², in I
  double gravity{9.81};                            // m/s², g_G = [0, 0, -gravity]
};

struct CameraSimConfig {
  double rate_hz{10.0};
  /// cam0 [, cam1]: the cameras simulated (camera_id = index).
  std::vector<CameraCalibration> calibrations;
  double pixel_noise{1.0};              // px, σ per image axis
  double min_depth{0.2};                // m, along the optical axis
  double max_range{30.0};               // m, Euclidean distance camera-point
  double max_depth{0.0};                // m, along the optical axis; 0 = no limit
  double border{0.0};                   // px margin inside the image
  double track_loss_probability{0.02};  // per track and frame
  /// > 0 (OpenVINS simulator mode): spawn static points in view whenever a
  /// camera sees fewer than this many static points, and report at most this
  /// many static points per camera (tracked ones first); 0 = off.
  int keep_per_camera{0};
  double spawn_depth_min{5.0};          // m, depth of spawned points
  double spawn_depth_max{7.0};          // m
};

/// Static points on the floor (z = 0) and the four walls of the workspace
/// rectangle (from the scenario: paths' bounding box grown by `margin`, or
/// the room of the mono scenario).
struct MapConfig {
  int floor_points{0};
  int wall_points{0};
  double wall_height{5.0};  // m
  double margin{10.0};      // m, paper/trajectory scenarios only
};

/// The rigid target (paper) or object (mono): a box standing on the plane
/// z = base_height, points on its faces fixed in T, T at the box centre.
struct TargetConfig {
  bool enabled{true};                   // paper and mono scenarios only
  Eigen::Vector3d size{1.0, 1.0, 1.0};  // m, box extent along T's x, y, z
  double base_height{0.0};              // m, height of the box's bottom face
  int points_per_face{40};
  double edge_margin{0.05};             // m, points keep this far from face edges
  /// A face point is seen only if cos(angle between the face normal and
  /// the direction to the camera) exceeds this (0 = pure back-face culling).
  double min_view_cos{0.05};
};

/// One sinusoid per axis: amplitude[k] sin(2π frequency_hz[k] t + phase[k]).
struct Sinusoid3 {
  Eigen::Vector3d amplitude{Eigen::Vector3d::Zero()};
  Eigen::Vector3d frequency_hz{Eigen::Vector3d::Zero()};
  Eigen::Vector3d phase{Eigen::Vector3d::Zero()};  // rad
};

// ---- Target motion of the paper scenario (issue 15) ----------------------

enum class TargetMotion {
  kSemicircle,  // constant speed and turn rate (the paper's Sec. IV)
  kRcCar,       // RcCarConfig: speed and curvature varying, stops and starts
};
/// Parses "semicircle" / "rc_car"; throws std::invalid_argument.
TargetMotion target_motion_from_string(const std::string& name);

/// A ground vehicle driving like an RC car along a roughly semicircular
/// course of arc length π·radius (common/sim/rc_car_course.h). Drawn from
/// derive_seed(map_seed, ·), so Monte-Carlo runs share it as they share the map.
struct RcCarConfig {
  double speed_min{0.5};          // m/s, slowest cruising speed
  double speed_max{2.5};          // m/s, fastest cruising speed
  double max_acceleration{1.0};   // m/s², peak of every speed change
  double hold_min{2.0};           // s, time at one speed
  double hold_max{6.0};           // s
  double stop_probability{0.15};  // per speed change: stop instead
  double stop_min{1.0};           // s, standstill duration
  double stop_max{3.0};           // s
  /// The heading is the semicircle's plus a deviation δ(s), drawn at knots
  /// every ~heading_spacing m of arc, δ ~ U[-heading_deviation,
  /// heading_deviation], 0 at both ends (so the course turns by π).
  double heading_spacing{20.0};   // m
  double heading_deviation{0.25}; // rad
};

struct PaperScenarioConfig {
  double radius{50.0};          // m, radius of the target's semicircle
  double speed{1.5};            // m/s, target speed along the semicircle
  double target_start_angle{0.0};  // rad, polar angle of the start point
  double standoff{4.0};         // m, UAV behind the target along its path tangent
  double lateral_offset{0.0};   // m, UAV offset to the left of the path
  double height{3.0};           // m, UAV camera height above the floor
  /// Oscillation of the camera position in the path frame
  /// [along-track, left, up] (m, Hz, rad).
  Sinusoid3 oscillation{Eigen::Vector3d(0.5, 0.6, 0.4), Eigen::Vector3d(0.07, 0.15, 0.15),
                        Eigen::Vector3d(0.0, 0.0, 1.0)};
  double spline_dt{0.1};        // s, control pose spacing of both splines
  TargetMotion target_motion{TargetMotion::kSemicircle};
  RcCarConfig rc_car;           // target_motion rc_car only
};

struct TrajectoryScenarioConfig {
  std::string file;             // TUM trajectory (pose of I in G)
  /// Control pose spacing (s); 0 = OpenVINS rule max(mean file dt, 0.05).
  double spline_dt{0.0};
  /// Start where the body has moved this far along its path (m): OpenVINS's
  /// simulator starts only once the platform moves (its
  /// sim_distance_threshold, 1.2 m), so a side-by-side run must too. 0 =
  /// from the spline's first valid time.
  double start_distance{0.0};
};

/// Where the mono camera's position is defined.
enum class CameraAnchor {
  kWorld,              // base + velocity t + sinusoids, in G
  kObjectTranslation,  // object position + (base + velocity t + sinusoids), in G axes
  kObjectPose,         // rigidly attached to the object: in T, orientation fixed in T
};
enum class CameraPointing {
  kLookAtObject,  // optical axis at the object centre, x horizontal, + wobble
  kFixed,         // the look-at orientation of t = 0, held (+ wobble)
};
/// The mono object's orientation.
enum class ObjectHeading {
  kAlongVelocity,  // yaw follows the path's velocity (a vehicle)
  kFixed,          // the orientation of t = 0, held: pure translation
};
CameraAnchor camera_anchor_from_string(const std::string& name);
CameraPointing camera_pointing_from_string(const std::string& name);
ObjectHeading object_heading_from_string(const std::string& name);

struct MonoScenarioConfig {
  double duration{60.0};  // s
  /// Object path on its plane: centre + amplitude ∘ sin(2π f t + phase)
  /// (x, y); orientation per object_heading.
  Eigen::Vector2d object_center{0.0, 0.0};          // m
  Eigen::Vector2d object_amplitude{1.0, 0.6};       // m
  Eigen::Vector2d object_frequency_hz{0.05, 0.1};   // Hz
  Eigen::Vector2d object_phase{0.0, 0.0};           // rad
  ObjectHeading object_heading{ObjectHeading::kAlongVelocity};
  CameraAnchor anchor{CameraAnchor::kWorld};
  CameraPointing pointing{CameraPointing::kLookAtObject};
  Eigen::Vector3d camera_base{-2.2, 0.0, 1.4};      // m (in G, or offset per anchor)
  Eigen::Vector3d camera_velocity{0.0, 0.0, 0.0};   // m/s, constant-velocity term
  /// config/sim_mono.yaml's hand-held shake (why these values: there).
  std::vector<Sinusoid3> camera_translation{
      {Eigen::Vector3d(0.104, 0.067, 0.042), Eigen::Vector3d(0.37, 0.47, 0.61), Eigen::Vector3d(0.0, 0.5, 1.0)},
      {Eigen::Vector3d(0.026, 0.029, 0.018), Eigen::Vector3d(1.31, 1.07, 1.73), Eigen::Vector3d(1.0, 2.0, 0.3)}};
  /// Small rotation (rad, rotation vector in the camera frame) applied on top
  /// of the pointing: R_CtoG = R_pointing exp(wobble).
  std::vector<Sinusoid3> camera_wobble{
      {Eigen::Vector3d(0.04, 0.04, 0.06), Eigen::Vector3d(0.23, 0.29, 0.19), Eigen::Vector3d(0.0, 1.0, 2.0)}};
  Eigen::Vector2d room_min{-4.0, -4.0};  // m, static map rectangle (floor + walls)
  Eigen::Vector2d room_max{4.0, 4.0};    // m
  double spline_dt{0.05};                // s
};

/// Surface texture of the rendered images (common/sim/renderer.h).
enum class SurfaceTexture {
  kPattern,       // procedural multi-scale shapes (texture.h)
  kCheckerboard,  // squares of render.checker_square: corners at known positions (tests, calibration)
};
SurfaceTexture surface_texture_from_string(const std::string& name);

/// The rendered images (vimot-sim --render, sim::Renderer); ignored by the
/// measurement-level simulation.
struct RenderConfig {
  double texel_size{0.004};   // m, scene texture resolution (mip level 0)
  int texture_size{2048};     // texels, side of the scene textures (power of 2); they repeat every side · texel_size
  int target_texture_size{512};  // texels along the longest edge of the target (power of 2)
  SurfaceTexture scene_texture{SurfaceTexture::kPattern};
  SurfaceTexture target_texture{SurfaceTexture::kPattern};
  double checker_square{0.5};  // m, square of the checkerboard textures
  double noise_sigma{2.0};     // grey levels, σ of the white image noise (0 = none)
  /// Exposure: every image's grey values are multiplied by
  /// exp(exposure_amplitude sin(2π exposure_frequency_hz t + φ)), φ from the seed.
  double exposure_amplitude{0.1};
  double exposure_frequency_hz{0.05};  // Hz
  /// Share of the target's light that is ambient (light from the room,
  /// the same on every face); the rest, 1 − target_ambient, comes from a
  /// fixed light from above (Lambert). 0.45 is a single strong light: the
  /// faces turned from it show their texture at less than half the
  /// contrast of the lit top.
  double target_ambient{0.45};
};

struct SimConfig {
  Scenario scenario{Scenario::kPaper};
  uint64_t seed{1};       // measurement noise: IMU, pixels, track loss
  uint64_t map_seed{1};   // static map, target points, spawned points
  int64_t start_utime{1000000};  // µs, time stamp of the first IMU sample
  /// s; 0 = the scenario's natural length (paper: the semicircle, mono:
  /// mono.duration, trajectory: the whole file). The splines and the map
  /// always cover at least the natural length, so a shorter run is an exact
  /// prefix of the full run's events.
  double duration{0.0};
  bool ground_truth_events{true};  // emit GroundTruth at IMU rate
  ImuSimConfig imu;
  CameraSimConfig camera;
  MapConfig map{2000, 2000, 5.0, 10.0};
  TargetConfig target;
  PaperScenarioConfig paper;
  TrajectoryScenarioConfig trajectory;
  MonoScenarioConfig mono;
  RenderConfig render;
};

/// Seed of random stream `stream` of `seed` (splitmix64 mixing): the
/// simulator's streams (IMU noise, pixel noise, track loss, map) are
/// independent, so e.g. changing a camera setting leaves the IMU noise alone.
uint64_t derive_seed(uint64_t seed, uint64_t stream);

/// Always-on input check: throws std::invalid_argument naming the field
/// and the offending value (negative rate, empty camera list, ...).
void validate(const SimConfig& config);

/// Reads a SimConfig from a config/sim_*.yaml file (see docs/simulator.md).
/// Keys absent from the file keep the struct defaults, except the camera
/// calibration and IMU noise densities, which come from the file named by
/// `calibration_file` (relative to the config's directory) or from the
/// config itself. `${VAR}` in `trajectory.file` expands an environment
/// variable. Throws ConfigError naming the file and the full key for a
/// missing, malformed, unknown or invalid key.
SimConfig from_config(const Config& config);

}  // namespace sim
}  // namespace vimot

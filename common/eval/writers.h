#pragma once
// Text outputs of the evaluators: TUM trajectories, per-frame error CSVs
// (with 3σ bounds), and the JSON summary block. No LCM, no JSON library.

#include <Eigen/Core>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "common/eval/json.h"
#include "common/eval/metrics.h"

namespace vimot {
namespace eval {

struct FrameSample;

struct StampedPose {
  int64_t utime{0};                                 // µs
  Eigen::Vector4d q_GtoI{0.0, 0.0, 0.0, 1.0};       // JPL
  Eigen::Vector3d p_IinG{Eigen::Vector3d::Zero()};   // m
};

/// utime as seconds with exactly 6 decimals, from the integer ("12.000345").
std::string utime_to_seconds_string(int64_t utime);

/// One TUM line "t x y z qx qy qz qw": t in s (µs precision), p_IinG in m,
/// the Hamilton body-to-world quaternion (jpl_GtoI_to_hamilton_ItoG).
std::string tum_line(const StampedPose& pose);

/// A TUM file: `comment` lines (prefixed "# "), then one line per pose.
/// Throws std::runtime_error if the file cannot be written.
void write_tum(const std::string& path, const std::vector<StampedPose>& poses, const std::string& comment = "");

std::vector<StampedPose> estimate_poses(const std::vector<FrameSample>& samples);
std::vector<StampedPose> truth_poses(const std::vector<FrameSample>& samples);

/// CSV header of write_errors_csv.
extern const char* const kErrorsCsvHeader;

/// Per-sample errors, one row per sample:
///   t, err_px, err_py, err_pz (m), err_rx, err_ry, err_rz (deg),
///   sig3_px, sig3_py, sig3_pz (m), sig3_rx, sig3_ry, sig3_rz (deg), nees_p, nees_r
/// t in s as in TUM files. Throws std::runtime_error if it cannot write.
void write_errors_csv(const std::string& path, const std::vector<ErrorSample>& errors);
void write_errors_csv(std::ostream& out, const std::vector<ErrorSample>& errors);

std::vector<ErrorSample> errors_of(const std::vector<FrameSample>& samples);

/// Writes an ErrorSummary as a JSON object (keys rmse_position_m,
/// rmse_orientation_deg, nees_position, nees_orientation, samples) at the
/// writer's current position.
void write_summary_json(JsonWriter& json, const ErrorSummary& summary);

/// The ErrorSummary of an object written with write_summary_json. Throws
/// std::runtime_error on a missing key or a wrong type.
ErrorSummary summary_from_json(const JsonValue& object);

/// Reads the object at `key` of a JSON file written with write_summary_json
/// (e.g. key "summary"; a path "cells/1/per_run/0/target_in_imu" walks
/// objects and arrays). Throws std::runtime_error naming the file and key.
ErrorSummary read_summary_json(const std::string& path, const std::string& key = "summary");

/// The whole file; throws std::runtime_error naming it if it cannot be read.
std::string read_text_file(const std::string& path);

/// Writes `text` to `path`, throwing std::runtime_error on failure.
void write_text_file(const std::string& path, const std::string& text);

}  // namespace eval
}  // namespace vimot

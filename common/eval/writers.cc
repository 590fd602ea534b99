#include "common/eval/writers.h"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/eval/sim_runner.h"
#include "common/math/quat.h"

namespace vimot {
namespace eval {

namespace {
constexpr double kRadToDeg = 180.0 / M_PI;

std::ofstream open_for_writing(const std::string& path) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write '" + path + "'");
  return f;
}

void finish(std::ofstream& f, const std::string& path) {
  f.flush();
  if (!f) throw std::runtime_error("error writing '" + path + "'");
}
}  // namespace

std::string utime_to_seconds_string(int64_t utime) {
  const bool negative = utime < 0;
  const uint64_t a = negative ? static_cast<uint64_t>(-(utime + 1)) + 1 : static_cast<uint64_t>(utime);
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%s%" PRIu64 ".%06" PRIu64, negative ? "-" : "", a / 1000000, a % 1000000);
  return buf;
}

std::string tum_line(const StampedPose& pose) {
  const Eigen::Vector4d q = jpl_GtoI_to_hamilton_ItoG(pose.q_GtoI);
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%s %.9f %.9f %.9f %.12f %.12f %.12f %.12f", utime_to_seconds_string(pose.utime).c_str(),
                pose.p_IinG.x(), pose.p_IinG.y(), pose.p_IinG.z(), q(0), q(1), q(2), q(3));
  return buf;
}

void write_tum(const std::string& path, const std::vector<StampedPose>& poses, const std::string& comment) {
  std::ofstream f = open_for_writing(path);
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) f << "# " << line << "\n";
  for (const StampedPose& p : poses) f << tum_line(p) << "\n";
  finish(f, path);
}

std::vector<StampedPose> estimate_poses(const std::vector<FrameSample>& samples) {
  std::vector<StampedPose> out;
  out.reserve(samples.size());
  for (const FrameSample& s : samples) out.push_back(StampedPose{s.utime, s.q_GtoI, s.p_IinG});
  return out;
}

std::vector<StampedPose> truth_poses(const std::vector<FrameSample>& samples) {
  std::vector<StampedPose> out;
  out.reserve(samples.size());
  for (const FrameSample& s : samples) out.push_back(StampedPose{s.utime, s.q_GtoI_true, s.p_IinG_true});
  return out;
}

const char* const kErrorsCsvHeader =
    "t,err_px,err_py,err_pz,err_rx,err_ry,err_rz,sig3_px,sig3_py,sig3_pz,sig3_rx,sig3_ry,sig3_rz,nees_p,nees_r";

void write_errors_csv(std::ostream& f, const std::vector<ErrorSample>& errors) {
  f << kErrorsCsvHeader << "\n";
  char buf[512];
  for (const ErrorSample& e : errors) {
    const Eigen::Vector3d r = e.err_theta * kRadToDeg;
    const Eigen::Vector3d sr = e.sig3_theta * kRadToDeg;
    std::snprintf(buf, sizeof(buf),
                  "%s,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g",
                  utime_to_seconds_string(e.utime).c_str(), e.err_p.x(), e.err_p.y(), e.err_p.z(), r.x(), r.y(), r.z(),
                  e.sig3_p.x(), e.sig3_p.y(), e.sig3_p.z(), sr.x(), sr.y(), sr.z(), e.nees_p, e.nees_theta);
    f << buf << "\n";
  }
}

void write_errors_csv(const std::string& path, const std::vector<ErrorSample>& errors) {
  std::ofstream f = open_for_writing(path);
  write_errors_csv(f, errors);
  finish(f, path);
}

std::vector<ErrorSample> errors_of(const std::vector<FrameSample>& samples) {
  std::vector<ErrorSample> out;
  out.reserve(samples.size());
  for (const FrameSample& s : samples) out.push_back(s.error);
  return out;
}

void write_summary_json(JsonWriter& json, const ErrorSummary& s) {
  json.begin_object();
  json.field("rmse_position_m", s.rmse_position_m);
  json.field("rmse_orientation_deg", s.rmse_orientation_deg);
  json.field("nees_position", s.nees_position);
  json.field("nees_orientation", s.nees_orientation);
  json.field("predicted_rmse_position_m", s.predicted_rmse_position_m);
  json.field("predicted_rmse_orientation_deg", s.predicted_rmse_orientation_deg);
  json.field("samples", s.count);
  json.end_object();
}

ErrorSummary summary_from_json(const JsonValue& o) {
  ErrorSummary s;
  s.rmse_position_m = o.at("rmse_position_m").number();
  s.rmse_orientation_deg = o.at("rmse_orientation_deg").number();
  s.nees_position = o.at("nees_position").number();
  s.nees_orientation = o.at("nees_orientation").number();
  s.predicted_rmse_position_m = o.at("predicted_rmse_position_m").number();
  s.predicted_rmse_orientation_deg = o.at("predicted_rmse_orientation_deg").number();
  s.count = static_cast<int64_t>(o.at("samples").number());
  return s;
}

ErrorSummary read_summary_json(const std::string& path, const std::string& key) {
  const std::string text = read_text_file(path);
  try {
    const JsonValue doc = JsonValue::parse(text);
    const JsonValue* node = &doc;
    std::size_t begin = 0;
    while (begin <= key.size()) {
      const std::size_t end = std::min(key.find('/', begin), key.size());
      const std::string part = key.substr(begin, end - begin);
      const bool index = !part.empty() && part.find_first_not_of("0123456789") == std::string::npos;
      node = index && !node->is_object() ? &node->at(static_cast<std::size_t>(std::stoul(part))) : &node->at(part);
      begin = end + 1;
    }
    return summary_from_json(*node);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error("'" + path + "' (object '" + key + "'): " + e.what());
  }
}

std::string read_text_file(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read '" + path + "'");
  std::stringstream text;
  text << f.rdbuf();
  return text.str();
}

void write_text_file(const std::string& path, const std::string& text) {
  std::ofstream f = open_for_writing(path);
  f << text;
  finish(f, path);
}

}  // namespace eval
}  // namespace vimot

#include "common/sim/trajectory_file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/math/quat.h"

namespace vimot {
namespace sim {

namespace {

// A quaternion written with ~9 digits has |q| within 1e-8 of 1; 1e-3 still
// rejects a mistyped component or a column in the wrong place.
constexpr double kQuatNormTolerance = 1e-3;

[[noreturn]] void fail(const std::string& source, int line, const std::string& what) {
  throw std::runtime_error("trajectory file '" + source + "', line " + std::to_string(line) + ": " + what);
}

}  // namespace

PoseTrajectory load_tum_trajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("trajectory file '" + path + "': cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw std::runtime_error("trajectory file '" + path + "': read error");
  return parse_tum_trajectory(buffer.str(), path);
}

PoseTrajectory parse_tum_trajectory(const std::string& text, const std::string& source) {
  PoseTrajectory traj;
  traj.path = source;
  std::istringstream lines(text);
  std::string line;
  int line_no = 0;
  long double t_first = 0.0L;
  long double t_prev = 0.0L;
  int prev_line = 0;
  while (std::getline(lines, line)) {
    ++line_no;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream tokens(line);
    std::vector<std::string> fields;
    std::string tok;
    while (tokens >> tok) fields.push_back(tok);
    if (fields.empty()) continue;
    if (fields.size() != 8) {
      fail(source, line_no, "expected 8 numbers 't x y z qx qy qz qw', got " + std::to_string(fields.size()) +
                                " field(s)");
    }
    // The time is parsed in long double and made relative to the first
    // pose, so epoch-sized stamps (1.5e9 s) keep sub-microsecond precision.
    long double values[8];
    for (int k = 0; k < 8; ++k) {
      const char* begin = fields[static_cast<std::size_t>(k)].c_str();
      char* end = nullptr;
      errno = 0;
      values[k] = std::strtold(begin, &end);
      if (end == begin || *end != '\0' || errno == ERANGE || !std::isfinite(static_cast<double>(values[k]))) {
        fail(source, line_no, "field " + std::to_string(k + 1) + " '" + fields[static_cast<std::size_t>(k)] +
                                  "' is not a finite number");
      }
    }
    if (traj.poses.empty()) {
      t_first = values[0];
    } else if (!(values[0] > t_prev)) {
      std::ostringstream msg;
      msg.precision(17);
      msg << "time " << static_cast<double>(values[0]) << " s does not increase (line " << prev_line << " has "
          << static_cast<double>(t_prev) << " s)";
      fail(source, line_no, msg.str());
    }
    t_prev = values[0];
    prev_line = line_no;
    const Eigen::Vector4d q(static_cast<double>(values[4]), static_cast<double>(values[5]),
                            static_cast<double>(values[6]), static_cast<double>(values[7]));
    if (std::abs(q.norm() - 1.0) > kQuatNormTolerance) {
      std::ostringstream msg;
      msg << "quaternion [" << q.transpose() << "] has norm " << q.norm() << ", not 1";
      fail(source, line_no, msg.str());
    }
    TimedPose pose;
    pose.t = static_cast<double>(values[0] - t_first);
    pose.R_BtoG = quat_to_rot(hamilton_ItoG_to_jpl_GtoI(q)).transpose();
    pose.p_BinG = Eigen::Vector3d(static_cast<double>(values[1]), static_cast<double>(values[2]),
                                  static_cast<double>(values[3]));
    traj.poses.push_back(pose);
  }
  if (traj.poses.size() < 2) {
    throw std::runtime_error("trajectory file '" + source + "': needs at least 2 poses, has " +
                             std::to_string(traj.poses.size()));
  }
  traj.t_first = static_cast<double>(t_first);
  return traj;
}

}  // namespace sim
}  // namespace vimot

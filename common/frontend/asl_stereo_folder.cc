#include "common/frontend/asl_stereo_folder.h"

#include <fstream>
#include <map>
#include <stdexcept>

namespace vimot::frontend {

namespace {

// timestamp -> image path of one camera folder.
std::map<int64_t, std::string> read_camera(const std::string& cam_dir, bool required) {
  std::map<int64_t, std::string> out;
  const std::string csv = cam_dir + "/data.csv";
  std::ifstream in(csv);
  if (!in) {
    if (required) throw std::runtime_error("ASL folder: cannot open " + csv);
    return out;
  }
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const auto comma = line.find(',');
    std::size_t used = 0;
    int64_t t = 0;
    try {
      t = std::stoll(line.substr(0, comma), &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (comma == std::string::npos || used != comma || comma + 1 >= line.size()) {
      throw std::runtime_error(csv + ":" + std::to_string(line_no) + ": expected 'timestamp_ns,filename', got '" +
                               line + "'");
    }
    const std::string path = cam_dir + "/data/" + line.substr(comma + 1);
    if (std::ifstream(path).good()) out.emplace(t, path);
  }
  return out;
}

}  // namespace

std::vector<AslStereoPair> read_asl_stereo_pairs(const std::string& mav0_dir) {
  const std::map<int64_t, std::string> left = read_camera(mav0_dir + "/cam0", true);
  const std::map<int64_t, std::string> right = read_camera(mav0_dir + "/cam1", false);
  std::vector<AslStereoPair> out;
  for (const auto& [t, path] : left) {
    AslStereoPair p;
    p.timestamp_ns = t;
    p.left_path = path;
    const auto it = right.find(t);
    if (it != right.end()) p.right_path = it->second;
    out.push_back(p);
  }
  return out;
}

}  // namespace vimot::frontend

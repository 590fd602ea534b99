#include "drivers/euroc_player/euroc_player.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>

#include <opencv2/imgcodecs.hpp>

#include "common/config/config.h"
#include "common/math/quat.h"

namespace vimot {
namespace euroc {
namespace {

namespace fs = std::filesystem;

// One data line of a CSV file, split on commas, fields trimmed.
struct CsvRow {
  int line{0};  // 1-based
  std::string text;
  std::vector<std::string> fields;
};

std::string trim(const std::string& s) {
  const std::size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const std::size_t e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// ASL CSVs: '#' header lines, comma-separated fields; files written on
// Windows end lines with '\r', which is not part of the last field.
std::vector<CsvRow> read_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in.good()) throw EurocError("cannot open '" + path + "'");
  std::vector<CsvRow> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    CsvRow row;
    row.line = number;
    row.text = line;
    std::size_t start = 0;
    while (true) {
      const std::size_t comma = t.find(',', start);
      row.fields.push_back(trim(t.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

[[noreturn]] void row_error(const std::string& path, const CsvRow& row, const std::string& what) {
  throw EurocError(path + ":" + std::to_string(row.line) + ": " + what + " in '" + row.text + "'");
}

// Timestamps are integers of ~1.4e18 ns: beyond a double's 53 bits, so they
// are parsed as integers, never through a double.
int64_t parse_ns(const std::string& path, const CsvRow& row) {
  const std::string& f = row.fields[0];
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(f.c_str(), &end, 10);
  if (f.empty() || *end != '\0' || errno == ERANGE || v < 0) {
    row_error(path, row, "timestamp '" + f + "' is not a non-negative integer (ns)");
  }
  return static_cast<int64_t>(v);
}

double parse_number(const std::string& path, const CsvRow& row, std::size_t i) {
  const std::string& f = row.fields[i];
  char* end = nullptr;
  const double v = std::strtod(f.c_str(), &end);
  if (f.empty() || *end != '\0' || !std::isfinite(v)) {
    row_error(path, row, "field " + std::to_string(i + 1) + " '" + f + "' is not a finite number");
  }
  return v;
}

Eigen::Vector3d parse_vec3(const std::string& path, const CsvRow& row, std::size_t first) {
  return Eigen::Vector3d(parse_number(path, row, first), parse_number(path, row, first + 1),
                         parse_number(path, row, first + 2));
}

// The data rows of an ASL CSV with a strictly increasing ns timestamp first
// and one of `field_counts` fields; parse(row, ns) makes the entry.
template <typename Entry, typename Parse>
std::vector<Entry> read_timed_csv(const std::string& path, const std::vector<std::size_t>& field_counts,
                                  const std::string& layout, Parse parse) {
  std::vector<Entry> entries;
  int64_t previous = -1;
  for (const CsvRow& row : read_csv(path)) {
    if (std::find(field_counts.begin(), field_counts.end(), row.fields.size()) == field_counts.end()) {
      row_error(path, row, "expected " + layout + ", got " + std::to_string(row.fields.size()) + " fields");
    }
    const int64_t ns = parse_ns(path, row);
    if (ns <= previous) {
      row_error(path, row,
                "timestamp " + std::to_string(ns) + " does not increase (previous " + std::to_string(previous) + ")");
    }
    previous = ns;
    entries.push_back(parse(row, ns));
  }
  return entries;
}

struct CameraEntry {
  int64_t ns{0};
  std::string file;  // full path
  int line{0};
};

std::vector<CameraEntry> read_camera_csv(const std::string& cam_dir) {
  const std::string path = cam_dir + "/data.csv";
  return read_timed_csv<CameraEntry>(path, {2}, "2 fields 'timestamp [ns],filename'",
                                     [&](const CsvRow& row, int64_t ns) {
                                       if (row.fields[1].empty()) row_error(path, row, "empty file name");
                                       return CameraEntry{ns, cam_dir + "/data/" + row.fields[1], row.line};
                                     });
}

struct TimedImu {
  int64_t ns;
  ImuData imu;
};

std::vector<TimedImu> read_imu_csv(const std::string& path) {
  return read_timed_csv<TimedImu>(path, {7}, "7 fields 'timestamp [ns],wx,wy,wz,ax,ay,az'",
                                  [&](const CsvRow& row, int64_t ns) {
                                    TimedImu s{ns, {}};
                                    s.imu.utime = ns_to_utime(ns);
                                    s.imu.w_IinI = parse_vec3(path, row, 1);
                                    s.imu.a_IinI = parse_vec3(path, row, 4);
                                    return s;
                                  });
}

struct TimedTruth {
  int64_t ns;
  GroundTruth truth;
};

std::vector<TimedTruth> read_groundtruth_csv(const std::string& path) {
  return read_timed_csv<TimedTruth>(
      path, {8, 11, 17}, "8, 11 or 17 fields 'time[ns],px,py,pz,qw,qx,qy,qz[,vx,vy,vz[,bwx,bwy,bwz,bax,bay,baz]]'",
      [&](const CsvRow& row, int64_t ns) {
        TimedTruth t{ns, {}};
        t.truth.utime = ns_to_utime(ns);
        t.truth.p_IinG = parse_vec3(path, row, 1);
        // EuRoC writes the Hamilton q_ItoG scalar first (w, x, y, z).
        const Eigen::Vector4d q_hamilton(parse_number(path, row, 5), parse_number(path, row, 6),
                                         parse_number(path, row, 7), parse_number(path, row, 4));
        if (std::abs(q_hamilton.norm() - 1.0) > 1e-3) {
          row_error(path, row, "quaternion norm " + std::to_string(q_hamilton.norm()) + " is not 1");
        }
        t.truth.q_GtoI = quat_normalize(hamilton_ItoG_to_jpl_GtoI(q_hamilton));
        if (row.fields.size() >= 11) t.truth.v_IinG = parse_vec3(path, row, 8);
        if (row.fields.size() == 17) {
          t.truth.bias_gyro = parse_vec3(path, row, 11);
          t.truth.bias_accel = parse_vec3(path, row, 14);
        }
        return t;
      });
}

// Image size from an ASL camera sensor.yaml ("resolution: [w, h]").
cv::Size read_resolution(const std::string& cam_dir) {
  const std::string path = cam_dir + "/sensor.yaml";
  if (!fs::is_regular_file(path)) throw EurocError("missing '" + path + "'");
  const std::vector<double> r = Config::load_file(path).get_vector("resolution", 2);
  if (!(r[0] >= 1.0 && r[1] >= 1.0) || r[0] != std::floor(r[0]) || r[1] != std::floor(r[1])) {
    throw EurocError(path + ": resolution must be two positive integers [width, height]");
  }
  return cv::Size(static_cast<int>(r[0]), static_cast<int>(r[1]));
}

std::string find_mav0(const std::string& dataset) {
  if (dataset.empty()) throw EurocError("no dataset folder given");
  if (!fs::is_directory(dataset)) throw EurocError("dataset folder '" + dataset + "' does not exist");
  if (fs::is_directory(fs::path(dataset) / "mav0")) return (fs::path(dataset) / "mav0").string();
  if (fs::is_directory(fs::path(dataset) / "cam0")) return dataset;
  throw EurocError("'" + dataset + "' is not an ASL dataset folder: it has neither mav0/ nor cam0/");
}

int64_t seconds_to_ns(double s) { return static_cast<int64_t>(std::llround(s * 1e9)); }

}  // namespace

int64_t ns_to_utime(int64_t ns) { return (ns + 500) / 1000; }

cv::Mat load_grey_image(const std::string& path, int width, int height) {
  if (!fs::is_regular_file(path)) throw EurocError("image '" + path + "' does not exist");
  const cv::Mat image = cv::imread(path, cv::IMREAD_UNCHANGED);
  if (image.empty()) throw EurocError("image '" + path + "' cannot be decoded (truncated or corrupt)");
  if (image.type() != CV_8UC1) {
    throw EurocError("image '" + path + "' is not 8-bit grey (" + std::to_string(image.channels()) +
                     " channels, depth code " + std::to_string(image.depth()) + ")");
  }
  if (image.cols != width || image.rows != height) {
    throw EurocError("image '" + path + "' is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                     ", sensor.yaml says " + std::to_string(width) + "x" + std::to_string(height));
  }
  return image;
}

EurocPlayer::EurocPlayer(const PlayerOptions& options) {
  if (!(options.start_s >= 0.0)) throw EurocError("start offset must be >= 0 s");
  if (!(options.duration_s >= 0.0)) throw EurocError("duration must be >= 0 s (0 = to the end)");
  if (!(options.imu_lead_s >= 0.0)) throw EurocError("IMU lead must be >= 0 s");
  const std::string mav0 = find_mav0(options.dataset);
  summary_.mav0 = mav0;
  for (const char* sub : {"cam0", "cam1", "imu0"}) {
    if (!fs::is_directory(mav0 + "/" + sub)) throw EurocError("missing folder '" + mav0 + "/" + sub + "'");
  }
  const cv::Size size_left = read_resolution(mav0 + "/cam0");
  const cv::Size size_right = read_resolution(mav0 + "/cam1");
  if (size_left != size_right) {
    throw EurocError(mav0 + ": cam0 and cam1 sensor.yaml give different resolutions");
  }
  summary_.width = size_left.width;
  summary_.height = size_left.height;

  // Pair the cameras on equal timestamps; a frame in one list only (e.g. the
  // slice's cam1 lists 4 frames past its last image) is skipped and counted.
  const std::vector<CameraEntry> left = read_camera_csv(mav0 + "/cam0");
  const std::vector<CameraEntry> right = read_camera_csv(mav0 + "/cam1");
  std::map<int64_t, const CameraEntry*> right_by_ns;
  for (const CameraEntry& e : right) right_by_ns[e.ns] = &e;
  std::vector<std::pair<const CameraEntry*, const CameraEntry*>> pairs;
  for (const CameraEntry& e : left) {
    const auto it = right_by_ns.find(e.ns);
    if (it == right_by_ns.end()) {
      ++summary_.unpaired_left;
    } else {
      pairs.emplace_back(&e, it->second);
    }
  }
  summary_.unpaired_right = static_cast<int64_t>(right.size() - pairs.size());
  if (pairs.empty()) throw EurocError(mav0 + ": cam0 and cam1 data.csv share no timestamp (no stereo pair)");

  const int64_t span_start = pairs.front().first->ns + seconds_to_ns(options.start_s);
  const int64_t span_end =
      options.duration_s > 0.0 ? span_start + seconds_to_ns(options.duration_s) : pairs.back().first->ns;
  for (const auto& [l, r] : pairs) {
    if (l->ns < span_start || l->ns > span_end) continue;
    for (const CameraEntry* e : {l, r}) {
      if (!fs::is_regular_file(e->file)) {
        const std::string cam = e == l ? "cam0" : "cam1";
        throw EurocError(mav0 + "/" + cam + "/data.csv:" + std::to_string(e->line) + " lists image '" + e->file +
                         "', which does not exist");
      }
    }
    events_.push_back(StereoFrame{ns_to_utime(l->ns), l->ns, l->file, r->file});
  }
  if (events_.empty()) {
    throw EurocError(mav0 + ": no stereo pair in the span (start " + std::to_string(options.start_s) +
                     " s, duration " + std::to_string(options.duration_s) + " s)");
  }
  const int64_t first_frame_ns = std::get<StereoFrame>(events_.front()).timestamp_ns;
  const int64_t last_frame_ns = std::get<StereoFrame>(events_.back()).timestamp_ns;
  summary_.stereo_pairs = static_cast<int64_t>(events_.size());
  summary_.span_start_utime = ns_to_utime(first_frame_ns);
  summary_.span_end_utime = ns_to_utime(last_frame_ns);

  // IMU and truth from the lead before the first pair through the first
  // sample at or after the last pair, so the last frame has IMU up to its time.
  const std::string imu_path = mav0 + "/imu0/data.csv";
  const std::vector<TimedImu> imu = read_imu_csv(imu_path);
  const int64_t lo = first_frame_ns - seconds_to_ns(options.imu_lead_s);
  const auto after_last =
      std::lower_bound(imu.begin(), imu.end(), last_frame_ns, [](const TimedImu& s, int64_t t) { return s.ns < t; });
  const int64_t hi = after_last == imu.end() ? last_frame_ns : after_last->ns;
  for (const TimedImu& s : imu) {
    if (s.ns >= lo && s.ns <= hi) events_.push_back(s.imu);
  }
  summary_.imu_samples = static_cast<int64_t>(events_.size()) - summary_.stereo_pairs;
  if (summary_.imu_samples == 0) throw EurocError(imu_path + " has no sample in the span of the images");

  if (options.use_groundtruth) {
    std::string gt_path = options.groundtruth_file;
    if (gt_path.empty()) {
      const std::string standard = mav0 + "/state_groundtruth_estimate0/data.csv";
      if (fs::is_regular_file(standard)) gt_path = standard;
    } else if (!fs::is_regular_file(gt_path)) {
      throw EurocError("ground truth file '" + gt_path + "' does not exist");
    }
    if (!gt_path.empty()) {
      summary_.groundtruth_file = gt_path;
      for (const TimedTruth& t : read_groundtruth_csv(gt_path)) {
        if (t.ns < lo || t.ns > hi) continue;
        events_.push_back(t.truth);
        ++summary_.groundtruth_poses;
      }
    }
  }

  std::stable_sort(events_.begin(), events_.end(), [](const PlayerEvent& a, const PlayerEvent& b) {
    const int64_t ta = std::visit([](const auto& e) { return e.utime; }, a);
    const int64_t tb = std::visit([](const auto& e) { return e.utime; }, b);
    return ta != tb ? ta < tb : a.index() < b.index();
  });
}

std::optional<PlayerEvent> EurocPlayer::next() {
  if (position_ >= events_.size()) return std::nullopt;
  return events_[position_++];
}

int64_t EurocPlayer::first_utime() const {
  return std::visit([](const auto& e) { return e.utime; }, events_.front());
}

int64_t EurocPlayer::last_utime() const {
  return std::visit([](const auto& e) { return e.utime; }, events_.back());
}

StereoImages EurocPlayer::load_images(const StereoFrame& frame) const {
  return {load_grey_image(frame.left_path, summary_.width, summary_.height),
          load_grey_image(frame.right_path, summary_.width, summary_.height)};
}

}  // namespace euroc
}  // namespace vimot

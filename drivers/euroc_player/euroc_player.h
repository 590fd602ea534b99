#pragma once
// Reader of an ASL (EuRoC MAV) dataset folder as one time-ordered stream of
// IMU samples, stereo pairs and ground truth. No LCM: vimot-euroc-player
// (main.cc) publishes the stream, tests and offline tools drive it directly.
//
// Layout read:
//   <dataset>/mav0/{cam0,cam1}/data.csv   "#timestamp [ns],filename"
//   <dataset>/mav0/{cam0,cam1}/data/<filename>   8-bit grey PNG
//   <dataset>/mav0/{cam0,cam1}/sensor.yaml       resolution [w, h]
//   <dataset>/mav0/imu0/data.csv          "#timestamp [ns],wx,wy,wz,ax,ay,az"
//   <dataset>/mav0/state_groundtruth_estimate0/data.csv (optional), or the
//     file of PlayerOptions::groundtruth_file, rows
//     "time[ns],px,py,pz,qw,qx,qy,qz[,vx,vy,vz[,bwx,bwy,bwz,bax,bay,baz]]":
//     the IMU (body) pose in the world, Hamilton quaternion of R_ItoG.
// <dataset> may also be the mav0 folder itself.
//
// Times: ns are rounded to the nearest µs (utime). Quaternions become JPL
// q_GtoI (common/math/quat.h). Ground truth carries pose, velocity and
// biases where the file gives them; w_IinI and a_IinG are not in EuRoC and
// stay zero.
//
// Everything is read and checked in the constructor (CSVs parsed, every
// image file of the span present), so a bad folder fails before the first
// message; the pixels are read lazily by load_images(). Errors throw
// EurocError naming the file (and line for CSVs).

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <opencv2/core.hpp>

#include "common/types/ground_truth.h"
#include "common/types/sensor_data.h"

namespace vimot {
namespace euroc {

class EurocError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct PlayerOptions {
  std::string dataset;           // folder holding mav0/, or mav0/ itself
  std::string groundtruth_file;  // "" = mav0/state_groundtruth_estimate0/data.csv if present
  bool use_groundtruth{true};    // false: no ground truth even if present
  double start_s{0.0};           // span start, s after the first stereo pair
  double duration_s{0.0};        // span length, s; 0 = up to the last stereo pair
  // IMU and ground truth start this long before the span's first pair, so a
  // static initialiser has its window when the images begin (clipped at the
  // start of the IMU stream).
  double imu_lead_s{1.0};
};

/// One synchronised stereo capture; images are loaded on demand.
struct StereoFrame {
  int64_t utime{0};         // µs
  int64_t timestamp_ns{0};  // as in data.csv
  std::string left_path;    // cam0 image
  std::string right_path;   // cam1 image
};

struct StereoImages {
  cv::Mat left;   // CV_8UC1
  cv::Mat right;  // CV_8UC1
};

/// At equal utime the order is IMU, ground truth, stereo pair: a consumer
/// that needs an IMU sample at or after a frame's time has it by the frame.
using PlayerEvent = std::variant<ImuData, GroundTruth, StereoFrame>;

struct PlayerSummary {
  std::string mav0;                // the mav0 folder read
  std::string groundtruth_file;    // "" when none is played
  int width{0};                    // image size from cam0/sensor.yaml
  int height{0};
  int64_t span_start_utime{0};     // first stereo pair of the span
  int64_t span_end_utime{0};       // last stereo pair of the span
  int64_t imu_samples{0};          // in the stream
  int64_t stereo_pairs{0};
  int64_t groundtruth_poses{0};
  // Frames listed by one camera's data.csv only (whole file): not played.
  int64_t unpaired_left{0};
  int64_t unpaired_right{0};
};

class EurocPlayer {
 public:
  explicit EurocPlayer(const PlayerOptions& options);

  const PlayerSummary& summary() const { return summary_; }

  /// The next event in time order, or nullopt at the end.
  std::optional<PlayerEvent> next();
  /// Back to the first event.
  void rewind() { position_ = 0; }
  int64_t first_utime() const;
  int64_t last_utime() const;

  /// Reads both images of a pair, checked against the sensor.yaml size.
  StereoImages load_images(const StereoFrame& frame) const;

 private:
  PlayerSummary summary_;
  std::vector<PlayerEvent> events_;
  std::size_t position_{0};
};

/// ASL nanoseconds -> utime, rounded to the nearest microsecond.
int64_t ns_to_utime(int64_t ns);

/// Reads an 8-bit grey image and checks its size. Throws EurocError naming
/// the file if it is missing, not a decodable image (truncated or corrupt
/// PNG), not 8-bit single-channel, or not width × height.
cv::Mat load_grey_image(const std::string& path, int width, int height);

}  // namespace euroc
}  // namespace vimot

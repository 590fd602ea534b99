#pragma once
// vimot-camera's logic, no LCM: one camera (mono) or two (stereo) read in
// turn, each frame stamped (FrameClock), converted to 8-bit grey at the
// configured size (to_grey), and, in stereo, paired by time (StereoPairer).
//
// A device that stops delivering (a failed read: unplugged, USB reset,
// V4L2 timeout) is closed and reopened after a back-off that starts at
// reopen_initial_s and doubles on each failed attempt up to reopen_max_s;
// its FrameClock is kept, so stamps stay increasing across the gap. A file
// that ends is finished, never reopened. Opening fails loudly at
// construction (CameraError naming the camera and device or file).

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "drivers/camera/frame_clock.h"
#include "drivers/camera/stereo_pairer.h"
#include "drivers/camera/video_source.h"

namespace vimot::camera {

struct CameraOptions {
  bool stereo{false};
  int width{0};  // px, every published image
  int height{0};
  bool resize{false};                                       // scale a frame of another size instead of failing
  double fps{0.0};                                          // Hz; file-rate stamps when the file gives no rate
  TimestampMode file_timestamps{TimestampMode::kFileRate};  // devices always use kHost
  double latency_s{0.0};                                    // host stamp − exposure time
  int64_t file_start_utime{0};                              // file-rate stamp of a file's first frame
  double stereo_tolerance_s{0.005};
  std::size_t max_waiting{4};  // frames one camera queues while the other delivers none
  double reopen_initial_s{0.5};
  double reopen_max_s{8.0};
};

/// Cumulative over the run (and over reopens). Index 0 = left, 1 = right.
struct CameraCounters {
  std::array<int64_t, 2> frames{};          // delivered by the source
  std::array<int64_t, 2> non_increasing{};  // dropped: stamp not after the last
  std::array<int64_t, 2> unpaired{};        // dropped: no partner within the tolerance
  int64_t published{0};                     // images (mono) or pairs (stereo) out
  int64_t stalls{0};                        // a device stopped delivering
  int64_t reopens{0};                       // a stalled device opened again
  int64_t reopen_failures{0};               // attempts that failed
};

/// The counters as (name, value) for the heartbeat, in a fixed order.
std::vector<std::pair<std::string, int64_t>> named_counters(const CameraCounters& c);

/// One published frame: `right` is empty in mono.
struct OutputFrame {
  int64_t utime{0};
  cv::Mat left;
  cv::Mat right;
};

class CameraDriver {
 public:
  /// `openers`: one (mono) or two (stereo: left, right), each opened now.
  /// `clock`: host time, µs (stamps and reopen back-off). `notice`: logs
  /// a stall or a reopen. Throws CameraError if a source cannot be opened
  /// or a file gives no frame rate and options.fps is 0.
  CameraDriver(const CameraOptions& options, std::vector<SourceOpener> openers, std::function<int64_t()> clock,
               std::function<void(const std::string&)> notice);

  /// Reads one frame from each camera that is open (trying a due reopen
  /// first) and returns the frames that became ready, in utime order.
  /// Throws CameraError for a frame that cannot be converted.
  std::vector<OutputFrame> step();

  /// Every camera's file has ended (never true with a device).
  bool finished() const;
  /// Some device is closed, waiting for its reopen.
  bool reopening() const;
  /// Every camera is a file stamped at its frame rate: the output is the
  /// same on every run, and paced by its utime.
  bool deterministic() const;
  /// Frame period of the first camera's file, s (0 for a device): the read
  /// pace of a host-stamped file.
  double file_period_s() const;

  const CameraCounters& counters() const { return counters_; }

 private:
  struct Camera {
    std::string name;
    SourceOpener opener;
    std::unique_ptr<FrameSource> source;
    bool file{false};
    bool ended{false};
    FrameClock clock;
    double period_s{0.0};
    double backoff_s{0.0};
    int64_t next_open_utime{0};
  };

  std::optional<cv::Mat> read(std::size_t index, int64_t now);

  CameraOptions options_;
  std::function<int64_t()> host_clock_;
  std::function<void(const std::string&)> notice_;
  std::vector<Camera> cameras_;
  StereoPairer pairer_;
  CameraCounters counters_;
};

}  // namespace vimot::camera

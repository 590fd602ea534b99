#include "drivers/camera/camera_driver.h"

#include <algorithm>
#include <sstream>

#include "common/time/utime.h"
#include "drivers/camera/grey_frame.h"

namespace vimot::camera {

namespace {

const char* const kNames[2] = {"left", "right"};

std::string seconds_text(double s) {
  std::ostringstream text;
  text << s << " s";
  return text.str();
}

}  // namespace

std::vector<std::pair<std::string, int64_t>> named_counters(const CameraCounters& c) {
  return {{"frames_left", c.frames[0]},
          {"frames_right", c.frames[1]},
          {"non_increasing_left", c.non_increasing[0]},
          {"non_increasing_right", c.non_increasing[1]},
          {"unpaired_left", c.unpaired[0]},
          {"unpaired_right", c.unpaired[1]},
          {"published", c.published},
          {"stalls", c.stalls},
          {"reopens", c.reopens},
          {"reopen_failures", c.reopen_failures}};
}

CameraDriver::CameraDriver(const CameraOptions& options, std::vector<SourceOpener> openers,
                           std::function<int64_t()> clock, std::function<void(const std::string&)> notice)
    : options_(options),
      host_clock_(std::move(clock)),
      notice_(std::move(notice)),
      pairer_(seconds_to_utime(options.stereo_tolerance_s), options.max_waiting) {
  if (openers.size() != (options_.stereo ? 2u : 1u)) {
    throw CameraError(std::string(options_.stereo ? "stereo" : "mono") + " camera needs " +
                      (options_.stereo ? "2" : "1") + " sources, got " + std::to_string(openers.size()));
  }
  if (options_.width <= 0 || options_.height <= 0) {
    throw CameraError("camera image size must be positive, got " + std::to_string(options_.width) + "x" +
                      std::to_string(options_.height));
  }
  for (std::size_t i = 0; i < openers.size(); ++i) {
    std::unique_ptr<FrameSource> source = openers[i]();
    const bool file = source->is_file();
    double fps = 0.0;
    TimestampMode mode = TimestampMode::kHost;
    if (file) {
      fps = source->file_fps() > 0.0 ? source->file_fps() : options_.fps;
      if (fps <= 0.0) {
        throw CameraError(std::string("camera ") + kNames[i] + ": the file gives no frame rate and image.fps is 0");
      }
      mode = options_.file_timestamps;
    }
    cameras_.push_back(Camera{kNames[i], std::move(openers[i]), std::move(source), file, false,
                              FrameClock(mode, seconds_to_utime(options_.latency_s), options_.file_start_utime, fps),
                              file ? 1.0 / fps : 0.0, options_.reopen_initial_s, 0});
  }
}

std::optional<cv::Mat> CameraDriver::read(std::size_t index, int64_t now) {
  Camera& cam = cameras_[index];
  if (cam.ended) return std::nullopt;
  if (!cam.source) {
    if (now < cam.next_open_utime) return std::nullopt;
    try {
      cam.source = cam.opener();
      ++counters_.reopens;
      notice_("camera " + cam.name + ": reopened");
    } catch (const CameraError& e) {
      ++counters_.reopen_failures;
      cam.backoff_s = std::min(2.0 * cam.backoff_s, options_.reopen_max_s);
      cam.next_open_utime = now + seconds_to_utime(cam.backoff_s);
      notice_(std::string(e.what()) + "; next attempt in " + seconds_text(cam.backoff_s));
      return std::nullopt;
    }
  }
  std::optional<cv::Mat> frame = cam.source->read();
  if (!frame) {
    if (cam.file) {
      cam.ended = true;
      cam.source.reset();
      return std::nullopt;
    }
    ++counters_.stalls;
    cam.source.reset();
    cam.next_open_utime = now + seconds_to_utime(cam.backoff_s);
    notice_("camera " + cam.name + ": device stopped delivering; reopening in " + seconds_text(cam.backoff_s));
    return std::nullopt;
  }
  cam.backoff_s = options_.reopen_initial_s;
  ++counters_.frames[index];
  return frame;
}

std::vector<OutputFrame> CameraDriver::step() {
  std::vector<OutputFrame> out;
  for (std::size_t i = 0; i < cameras_.size(); ++i) {
    std::optional<cv::Mat> frame = read(i, host_clock_());
    if (!frame) continue;
    // The host time right after the read: the frame reached us then.
    const std::optional<int64_t> utime = cameras_[i].clock.stamp(host_clock_());
    if (!utime) {
      counters_.non_increasing[i] = cameras_[i].clock.non_increasing();
      continue;
    }
    cv::Mat grey = to_grey(*frame, options_.width, options_.height, options_.resize, cameras_[i].name);
    if (options_.stereo) {
      pairer_.add(static_cast<int>(i), StampedFrame{*utime, std::move(grey)});
    } else {
      out.push_back(OutputFrame{*utime, std::move(grey), cv::Mat()});
    }
  }
  if (options_.stereo) {
    while (std::optional<StereoPair> pair = pairer_.next()) {
      out.push_back(OutputFrame{pair->utime, std::move(pair->left), std::move(pair->right)});
    }
    counters_.unpaired = {pairer_.unpaired(0), pairer_.unpaired(1)};
  }
  counters_.published += static_cast<int64_t>(out.size());
  return out;
}

bool CameraDriver::finished() const {
  return std::all_of(cameras_.begin(), cameras_.end(), [](const Camera& c) { return c.ended; });
}

bool CameraDriver::reopening() const {
  return std::any_of(cameras_.begin(), cameras_.end(), [](const Camera& c) { return !c.source && !c.ended; });
}

bool CameraDriver::deterministic() const {
  return options_.file_timestamps == TimestampMode::kFileRate &&
         std::all_of(cameras_.begin(), cameras_.end(), [](const Camera& c) { return c.file; });
}

double CameraDriver::file_period_s() const { return cameras_.front().period_s; }

}  // namespace vimot::camera

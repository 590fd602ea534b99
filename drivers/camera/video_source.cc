#include "drivers/camera/video_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <opencv2/videoio.hpp>

namespace vimot::camera {

namespace {

// V4L2's exposure_auto menu (linux/v4l2-controls.h), which OpenCV's V4L2
// backend passes through unchanged.
constexpr double kV4l2ExposureManual = 1.0;
constexpr double kV4l2ExposureAperturePriority = 3.0;
// V4L2 exposure_absolute counts 100 µs.
constexpr double kV4l2ExposureUnitS = 100e-6;

class VideoCaptureSource : public FrameSource {
 public:
  VideoCaptureSource(std::unique_ptr<cv::VideoCapture> capture, bool file, bool sequence, std::optional<cv::Mat> first)
      : capture_(std::move(capture)), file_(file), sequence_(sequence), first_(std::move(first)) {}

  std::optional<cv::Mat> read() override {
    if (first_) {
      std::optional<cv::Mat> frame = std::move(first_);
      first_.reset();
      return frame;
    }
    cv::Mat frame;
    if (!capture_->read(frame) || frame.empty()) return std::nullopt;
    return frame;
  }
  bool is_file() const override { return file_; }
  double file_fps() const override {
    // OpenCV reports 1 Hz for an image sequence, which has no rate.
    if (!file_ || sequence_) return 0.0;
    const double fps = capture_->get(cv::CAP_PROP_FPS);
    return std::isfinite(fps) && fps > 0.0 ? fps : 0.0;
  }

 private:
  std::unique_ptr<cv::VideoCapture> capture_;
  bool file_;
  bool sequence_;
  std::optional<cv::Mat> first_;  // read at open to prove the file decodes
};

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

std::unique_ptr<FrameSource> open_device(const std::string& camera, const std::string& spec,
                                         const DeviceRequest& request, DeviceReport* report) {
  // An index N is V4L2's /dev/videoN.
  const std::string path = all_digits(spec) ? "/dev/video" + spec : spec;
  if (!std::filesystem::exists(path)) {
    throw CameraError("camera " + camera + ": device " + path + " does not exist");
  }
  auto capture = std::make_unique<cv::VideoCapture>();
  const bool opened =
      all_digits(spec) ? capture->open(std::stoi(spec), cv::CAP_V4L2) : capture->open(spec, cv::CAP_V4L2);
  if (!opened || !capture->isOpened()) {
    throw CameraError("camera " + camera + ": cannot open device " + path +
                      " as a V4L2 capture device (busy, no permission, or not a camera)");
  }
  if (request.width > 0) capture->set(cv::CAP_PROP_FRAME_WIDTH, request.width);
  if (request.height > 0) capture->set(cv::CAP_PROP_FRAME_HEIGHT, request.height);
  if (request.fps > 0.0) capture->set(cv::CAP_PROP_FPS, request.fps);
  if (request.auto_exposure) {
    capture->set(cv::CAP_PROP_AUTO_EXPOSURE, kV4l2ExposureAperturePriority);
  } else {
    capture->set(cv::CAP_PROP_AUTO_EXPOSURE, kV4l2ExposureManual);
    capture->set(cv::CAP_PROP_EXPOSURE, request.exposure_s / kV4l2ExposureUnitS);
  }
  if (report != nullptr) {
    report->width = capture->get(cv::CAP_PROP_FRAME_WIDTH);
    report->height = capture->get(cv::CAP_PROP_FRAME_HEIGHT);
    report->fps = capture->get(cv::CAP_PROP_FPS);
    report->exposure = capture->get(cv::CAP_PROP_EXPOSURE);
  }
  return std::make_unique<VideoCaptureSource>(std::move(capture), false, false, std::nullopt);
}

std::unique_ptr<FrameSource> open_file(const std::string& camera, const std::string& spec) {
  const bool sequence = spec.find('%') != std::string::npos;
  const std::filesystem::path folder = std::filesystem::path(spec).parent_path();
  if (sequence ? !folder.empty() && !std::filesystem::is_directory(folder) : !std::filesystem::exists(spec)) {
    throw CameraError("camera " + camera + ": " +
                      (sequence ? "image sequence folder " + folder.string() : "video file " + spec) +
                      " does not exist");
  }
  if (!sequence && std::filesystem::is_directory(spec)) {
    throw CameraError("camera " + camera + ": video file " + spec + " is a directory");
  }
  auto capture = std::make_unique<cv::VideoCapture>();
  // FFmpeg alone for videos: the other backends' failed attempts on a bad
  // file only add noise to the log.
  if (!capture->open(spec, sequence ? cv::CAP_IMAGES : cv::CAP_FFMPEG) || !capture->isOpened()) {
    throw CameraError("camera " + camera + ": cannot read " + spec +
                      (sequence ? " (no image matches the pattern)" : " (not a video OpenCV can decode)"));
  }
  cv::Mat first;
  if (!capture->read(first) || first.empty()) {
    throw CameraError("camera " + camera + ": " + spec + " has no readable frame");
  }
  return std::make_unique<VideoCaptureSource>(std::move(capture), true, sequence, std::move(first));
}

}  // namespace

bool is_device_spec(const std::string& spec) { return spec.rfind("/dev/", 0) == 0 || all_digits(spec); }

std::unique_ptr<FrameSource> open_video_source(const std::string& camera, const std::string& spec,
                                               const DeviceRequest& request, DeviceReport* report) {
  return is_device_spec(spec) ? open_device(camera, spec, request, report) : open_file(camera, spec);
}

}  // namespace vimot::camera

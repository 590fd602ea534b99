#pragma once
// Where vimot-camera's frames come from: a V4L2 device or a video file
// through OpenCV's VideoCapture, behind an interface so the driver's logic
// (stamping, pairing, reopening) runs in tests on scripted sources.

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <stdexcept>
#include <string>

namespace vimot::camera {

/// A camera problem that stops the driver: what() names the camera and the
/// device or file.
class CameraError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// The next frame as delivered (any 8-bit type), or nullopt when none
  /// came: the end of a file, or a device that stopped delivering.
  virtual std::optional<cv::Mat> read() = 0;
  /// A file (ends; never reopened) rather than a live device.
  virtual bool is_file() const = 0;
  /// The file's frame rate, Hz (0 when it does not say, e.g. an image
  /// sequence); 0 for a device.
  virtual double file_fps() const = 0;
};

/// Opens a source; throws CameraError when it cannot.
using SourceOpener = std::function<std::unique_ptr<FrameSource>()>;

/// What a V4L2 device is asked for. Non-positive values leave the device's
/// own setting.
struct DeviceRequest {
  int width{0};
  int height{0};
  double fps{0.0};
  bool auto_exposure{true};
  double exposure_s{0.0};  // used when !auto_exposure
};

/// What the device reports after the request (VideoCapture::get; a driver
/// may round a request or ignore it, the driver checks every frame's size).
struct DeviceReport {
  double width{0.0};
  double height{0.0};
  double fps{0.0};
  double exposure{0.0};  // V4L2 exposure_absolute, units of 100 µs
};

/// A device spec is "/dev/..." or a bare index ("0"); anything else is a
/// file (a video, or an image sequence pattern such as "dir/frame_%04d.png").
bool is_device_spec(const std::string& spec);

/// Opens `spec` with OpenCV. `camera` names the camera in errors. Devices
/// get `request` (V4L2 backend) and their report in `report`, if given.
/// Throws CameraError for a missing device or file, one OpenCV cannot open,
/// or a file with no readable first frame.
std::unique_ptr<FrameSource> open_video_source(const std::string& camera, const std::string& spec,
                                               const DeviceRequest& request, DeviceReport* report = nullptr);

}  // namespace vimot::camera

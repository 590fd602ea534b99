#include "drivers/camera/grey_frame.h"

#include <opencv2/imgproc.hpp>

#include "drivers/camera/video_source.h"

namespace vimot::camera {

namespace {

std::string size_text(int width, int height) { return std::to_string(width) + "x" + std::to_string(height); }

}  // namespace

cv::Mat to_grey(const cv::Mat& frame, int width, int height, bool resize, const std::string& camera) {
  cv::Mat grey;
  switch (frame.type()) {
    case CV_8UC1:
      grey = frame.clone();  // the capture may reuse its buffer; frames wait in the pairer
      break;
    case CV_8UC3:
      cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
      break;
    case CV_8UC4:
      cv::cvtColor(frame, grey, cv::COLOR_BGRA2GRAY);
      break;
    default:
      throw CameraError("camera " + camera + ": frame of OpenCV type " + cv::typeToString(frame.type()) +
                        ", expected 8-bit grey, BGR or BGRA");
  }
  if (grey.cols == width && grey.rows == height) return grey;
  if (!resize) {
    throw CameraError("camera " + camera + ": frame is " + size_text(grey.cols, grey.rows) + ", configured " +
                      size_text(width, height) + " (image.resize: true scales it)");
  }
  cv::Mat scaled;
  cv::resize(grey, scaled, cv::Size(width, height), 0.0, 0.0, cv::INTER_AREA);
  return scaled;
}

}  // namespace vimot::camera

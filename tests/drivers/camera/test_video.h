#pragma once
// Short test videos with known content: frame i is a uniform BGR colour
// that identifies i (frame_colour), written losslessly (FFV1 in .avi,
// which Debian's OpenCV/FFmpeg encodes offline) so a decoded frame can be
// compared exactly.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <string>

namespace vimot::camera::test {

inline cv::Scalar frame_colour(int i) { return cv::Scalar(10 + 7 * i, 200 - 5 * i, 50 + 3 * i); }

/// Grey of frame i by the BT.601 luma weights, by hand.
inline double frame_grey(int i) {
  const cv::Scalar c = frame_colour(i);  // B, G, R
  return 0.114 * c[0] + 0.587 * c[1] + 0.299 * c[2];
}

/// Writes frames `first` .. `first + frames - 1` of width × height at
/// `fps`; returns false if the codec is unavailable.
inline bool write_test_video(const std::string& path, int frames, double fps, int width, int height, int first = 0) {
  cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), fps,
                         cv::Size(width, height), true);
  if (!writer.isOpened()) return false;
  for (int i = 0; i < frames; ++i) writer.write(cv::Mat(height, width, CV_8UC3, frame_colour(first + i)));
  return true;
}

/// A fresh folder under /tmp, removed with the object.
struct TempDir {
  TempDir() {
    char pattern[] = "/tmp/vimot_camera_XXXXXX";
    path = ::mkdtemp(pattern);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
  std::string path;
};

}  // namespace vimot::camera::test

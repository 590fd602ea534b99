// vimot-mask-filter over LCM on a private UDP URL: masks published on
// TARGET_MASK come back as boxes on TARGET_BOX at their utime, with the
// message fields filled from the filter; a mask with a wrong size field is
// counted as an error, and the process exits cleanly on SIGTERM.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "vimot/mask_t.hpp"
#include "vimot/target_box_t.hpp"

namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

constexpr int kW = 64, kH = 48;  // small masks: one UDP datagram each

vimot::mask_t rectangle_mask(int64_t utime, int x, int y, int w, int h) {
  vimot::mask_t m;
  m.utime = utime;
  m.camera_id = 0;
  m.width = kW;
  m.height = kH;
  m.size = kW * kH;
  m.data.assign(static_cast<std::size_t>(m.size), 0);
  for (int r = y; r < y + h; ++r) {
    for (int c = x; c < x + w; ++c) m.data[static_cast<std::size_t>(r * kW + c)] = 255;
  }
  return m;
}

struct Receiver {
  void on_box(const lcm::ReceiveBuffer*, const std::string&, const vimot::target_box_t* m) { boxes.push_back(*m); }
  std::vector<vimot::target_box_t> boxes;
};

}  // namespace

TEST_CASE("vimot-mask-filter: TARGET_MASK in, TARGET_BOX out over LCM") {
  const std::string tag = std::to_string(::getpid());
  const std::string config = "/tmp/mask_filter_process_test_" + tag + ".yaml";
  const std::string log = "/tmp/mask_filter_process_test_" + tag + ".txt";
  std::ofstream(config) << "mode: mono\n"
                           "cameras: {cam0: {resolution: [64, 48], intrinsics: [40, 40, 32, 24],\n"
                           "  distortion_model: radial-tangential, distortion_coefficients: [0, 0, 0, 0],\n"
                           "  T_BS: {rows: 4, cols: 4, data: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]}}}\n"
                           "filter: {morphology: {erode_kernel_px: 3, dilate_kernel_px: 3}, min_blob_area_px: 4}\n";
  // A URL of our own: other jobs on this machine use the default group.
  const std::string url = "udpm://239.255.77." + std::to_string(100 + ::getpid() % 100) + ":" +
                          std::to_string(7300 + ::getpid() % 250) + "?ttl=0";
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDERR_FILENO);
    ::dup2(fd, STDOUT_FILENO);
    ::execl(VIMOT_MASK_FILTER_BIN, VIMOT_MASK_FILTER_BIN, "--config", config.c_str(), "--lcm-url", url.c_str(),
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  for (int i = 0; i < 200 && read_file(log).find("started (pid") == std::string::npos; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));

  lcm::LCM lcm(url);
  REQUIRE(lcm.good());
  Receiver rx;
  lcm.subscribe("TARGET_BOX", &Receiver::on_box, &rx);
  vimot::mask_t bad = rectangle_mask(50000, 10, 10, 8, 6);
  bad.size = kW * kH - 1;  // the size field disagrees with width·height
  bad.data.resize(static_cast<std::size_t>(bad.size));
  lcm.publish("TARGET_MASK", &bad);
  constexpr int kMasks = 5;
  for (int k = 0; k < kMasks; ++k) {
    const vimot::mask_t m = rectangle_mask(100000 * (k + 1), 10 + k, 12, 8, 6);
    lcm.publish("TARGET_MASK", &m);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (rx.boxes.size() < kMasks && std::chrono::steady_clock::now() < deadline) lcm.handleTimeout(100);
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const std::string text = read_file(log);
  INFO(text);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  REQUIRE(rx.boxes.size() == kMasks);
  for (int k = 0; k < kMasks; ++k) {
    const vimot::target_box_t& b = rx.boxes[static_cast<std::size_t>(k)];
    CHECK(b.utime == 100000 * (k + 1));
    CHECK(b.camera_id == 0);
    CHECK(b.raw_valid);
    CHECK(b.raw_box[0] == 10 + k);
    CHECK(b.raw_box[1] == 12);
    CHECK(b.raw_box[2] == 8);
    CHECK(b.raw_box[3] == 6);
    CHECK(b.filtered_valid);
    CHECK(b.frames_since_raw == 0);
    CHECK(b.filtered_covariance[0] > 0.0);
    CHECK(b.filtered_covariance[1 * 4 + 0] == b.filtered_covariance[0 * 4 + 1]);
  }
  CHECK(rx.boxes.back().filtered_velocity[0] > 0.0);  // the box moves right
  CHECK(text.find("processed 5 masks (5 detections") != std::string::npos);
  CHECK(text.find("1 errors") != std::string::npos);
  std::remove(config.c_str());
  std::remove(log.c_str());
}

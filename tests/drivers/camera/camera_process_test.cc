// vimot-camera as a process over LCM on a private UDP URL: two generated
// videos as a stereo pair arrive on the configured channels, every frame,
// in order, grey, at their file-rate stamps, with a heartbeat that counts
// them; --help and a missing file exit as they should.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <chrono>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/drivers/camera/test_video.h"
#include "vimot/heartbeat_t.hpp"
#include "vimot/image_t.hpp"

using vimot::camera::test::frame_grey;
using vimot::camera::test::TempDir;

namespace {

constexpr int kW = 64, kH = 48;  // small images: one UDP datagram each

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Starts vimot-camera with `args`, output to `log`.
pid_t spawn(const std::vector<std::string>& args, const std::string& log) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, STDERR_FILENO);
    ::dup2(fd, STDOUT_FILENO);
    std::vector<char*> argv;
    argv.push_back(const_cast<char*>(VIMOT_CAMERA_BIN));
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(VIMOT_CAMERA_BIN, argv.data());
    ::_exit(127);
  }
  return pid;
}

int exit_code(pid_t pid) {
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

struct Receiver {
  void on_image(const lcm::ReceiveBuffer*, const std::string& channel, const vimot::image_t* m) {
    (channel == "CAM_LEFT_T" ? left : right).push_back(*m);
  }
  void on_heartbeat(const lcm::ReceiveBuffer*, const std::string&, const vimot::heartbeat_t* m) {
    if (m->name == "vimot-camera") heartbeat = *m;
  }
  std::vector<vimot::image_t> left, right;
  vimot::heartbeat_t heartbeat{};
};

int64_t counter(const vimot::heartbeat_t& hb, const std::string& name) {
  for (int i = 0; i < hb.num_counters; ++i) {
    if (hb.counter_names[static_cast<std::size_t>(i)] == name) return hb.counter_values[static_cast<std::size_t>(i)];
  }
  return -1;
}

}  // namespace

TEST_CASE("vimot-camera publishes a stereo pair of videos on its channels") {
  TempDir dir;
  constexpr int kFrames = 10;
  REQUIRE(vimot::camera::test::write_test_video(dir / "left.avi", kFrames, 20.0, kW, kH, 0));
  REQUIRE(vimot::camera::test::write_test_video(dir / "right.avi", kFrames, 20.0, kW, kH, 20));
  const std::string config = dir / "camera.yaml";
  std::ofstream(config) << "mode: stereo\nsources: {left: left.avi, right: right.avi}\n"
                           "image: {width: 64, height: 48}\ntiming: {file_start: 2.0}\n"
                           "channels: {cam_left: CAM_LEFT_T, cam_right: CAM_RIGHT_T, heartbeat: HEARTBEAT_T}\n";
  // A URL of our own: other jobs on this machine use the default group.
  const std::string url = "udpm://239.255.78." + std::to_string(100 + ::getpid() % 100) + ":" +
                          std::to_string(7400 + ::getpid() % 250) + "?ttl=0";
  lcm::LCM lcm(url);
  REQUIRE(lcm.good());
  Receiver rx;
  lcm.subscribe("CAM_LEFT_T", &Receiver::on_image, &rx);
  lcm.subscribe("CAM_RIGHT_T", &Receiver::on_image, &rx);
  lcm.subscribe("HEARTBEAT_T", &Receiver::on_heartbeat, &rx);

  const std::string log = dir / "camera.log";
  const pid_t pid = spawn({"--config", config, "--lcm-url", url, "--start-delay", "0.5", "--linger", "0.5"}, log);
  REQUIRE(pid > 0);
  int status = 0;
  pid_t done = 0;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (done == 0 && std::chrono::steady_clock::now() < deadline) {
    lcm.handleTimeout(50);
    done = ::waitpid(pid, &status, WNOHANG);
  }
  if (done == 0) {
    ::kill(pid, SIGKILL);
    ::waitpid(pid, &status, 0);
  }
  while (lcm.handleTimeout(100) > 0) {
  }
  INFO(read_text(log));
  REQUIRE(done == pid);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  REQUIRE(rx.left.size() == kFrames);
  REQUIRE(rx.right.size() == kFrames);
  for (int i = 0; i < kFrames; ++i) {
    INFO("frame " << i);
    const vimot::image_t& l = rx.left[static_cast<std::size_t>(i)];
    const vimot::image_t& r = rx.right[static_cast<std::size_t>(i)];
    CHECK(l.utime == 2'000'000 + 50'000 * i);
    CHECK(r.utime == l.utime);
    CHECK(l.width == kW);
    CHECK(l.height == kH);
    CHECK(l.pixelformat == vimot::image_t::PIXEL_FORMAT_GRAY);
    REQUIRE(l.size == kW * kH);
    CHECK(l.data[100] == Approx(frame_grey(i)).margin(1));
    CHECK(r.data[100] == Approx(frame_grey(20 + i)).margin(1));
  }
  CHECK(counter(rx.heartbeat, "published") == kFrames);
  CHECK(counter(rx.heartbeat, "frames_right") == kFrames);
  CHECK(counter(rx.heartbeat, "unpaired_left") == 0);
  CHECK(rx.heartbeat.messages_out >= 2 * kFrames);
}

TEST_CASE("vimot-camera --help and a missing video") {
  TempDir dir;
  const std::string log = dir / "out.log";
  CHECK(exit_code(spawn({"--help"}, log)) == 0);
  CHECK(read_text(log).find("CAM_LEFT") != std::string::npos);

  const std::string config = dir / "camera.yaml";
  std::ofstream(config) << "mode: mono\nsources: {left: absent.avi}\nimage: {width: 64, height: 48}\n";
  CHECK(exit_code(spawn({"--config", config, "--lcm-url", "memq://"}, log)) == 1);
  const std::string text = read_text(log);
  INFO(text);
  CHECK(text.find("camera left: video file " + (dir / "absent.avi") + " does not exist") != std::string::npos);
}

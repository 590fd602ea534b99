// The camera driver's library (no LCM, no camera): frames from generated
// videos and image sequences (count, order, content, file-rate stamps),
// host stamps with latency on a scripted clock, stereo pairing with an
// offset and a dropped frame, grey conversion, sizes, the reopen back-off
// of a device that stops delivering, and the errors for missing or bad
// sources and configs.
#include "drivers/camera/camera_driver.h"

#include <catch2/catch.hpp>
#include <deque>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "drivers/camera/camera_config.h"
#include "drivers/camera/frame_clock.h"
#include "drivers/camera/grey_frame.h"
#include "drivers/camera/stereo_pairer.h"
#include "drivers/euroc_player/euroc_player.h"
#include "tests/data_dir.h"
#include "tests/drivers/camera/test_video.h"

using namespace vimot::camera;
using vimot::camera::test::frame_colour;
using vimot::camera::test::frame_grey;
using vimot::camera::test::TempDir;

namespace {

constexpr int kW = 64, kH = 48;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "<no exception>";
}

CameraOptions file_options(bool stereo = false) {
  CameraOptions o;
  o.stereo = stereo;
  o.width = kW;
  o.height = kH;
  return o;
}

SourceOpener file_opener(const std::string& path) {
  return [path] { return open_video_source("left", path, DeviceRequest{}); };
}

std::vector<OutputFrame> run_to_end(CameraDriver& driver) {
  std::vector<OutputFrame> all;
  for (int guard = 0; guard < 1000 && !driver.finished(); ++guard) {
    for (OutputFrame& f : driver.step()) all.push_back(std::move(f));
  }
  REQUIRE(driver.finished());
  return all;
}

int64_t no_clock() { return 0; }
void quiet(const std::string&) {}

// A host clock the scripted sources set to each frame's arrival time.
struct FakeClock {
  int64_t now{0};
};

// A scripted source: frame k carries grey level `levels[k]` and arrives at
// `times[k]`; after the script, nullopt (a device stalls, a file ends).
class ScriptedSource : public FrameSource {
 public:
  ScriptedSource(FakeClock* clock, std::vector<int64_t> times, std::vector<int> levels, bool file)
      : clock_(clock), times_(std::move(times)), levels_(std::move(levels)), file_(file) {}
  std::optional<cv::Mat> read() override {
    if (next_ >= times_.size()) return std::nullopt;
    clock_->now = times_[next_];
    return cv::Mat(kH, kW, CV_8UC1, cv::Scalar(levels_[next_++]));
  }
  bool is_file() const override { return file_; }
  double file_fps() const override { return file_ ? 20.0 : 0.0; }

 private:
  FakeClock* clock_;
  std::vector<int64_t> times_;
  std::vector<int> levels_;
  bool file_;
  std::size_t next_{0};
};

}  // namespace

TEST_CASE("a video file: every frame in order, grey, stamped from the file's rate") {
  TempDir dir;
  const std::string video = dir / "clip.avi";
  constexpr int kFrames = 12;
  REQUIRE(test::write_test_video(video, kFrames, 30.0, kW, kH));
  CameraOptions o = file_options();
  o.file_start_utime = 5'000'000;
  o.latency_s = 0.25;  // host-stamp latency: no part of file-rate stamps
  CameraDriver driver(o, {file_opener(video)}, no_clock, quiet);
  CHECK(driver.deterministic());
  const std::vector<OutputFrame> frames = run_to_end(driver);
  REQUIRE(frames.size() == kFrames);
  for (int i = 0; i < kFrames; ++i) {
    const OutputFrame& f = frames[static_cast<std::size_t>(i)];
    INFO("frame " << i);
    // i / 30 Hz rounded to the µs from the index: 33333, 66667, 100000, ...
    CHECK(f.utime == 5'000'000 + std::llround(i * 1e6 / 30.0));
    REQUIRE(f.left.type() == CV_8UC1);
    CHECK(f.left.size() == cv::Size(kW, kH));
    CHECK(f.right.empty());
    double lo = 0, hi = 0;
    cv::minMaxLoc(f.left, &lo, &hi);
    CHECK(lo == hi);                               // uniform, as written
    CHECK(lo == Approx(frame_grey(i)).margin(1));  // OpenCV rounds its fixed-point weights
  }
  CHECK(frames[3].utime == 5'100'000);
  CHECK(driver.counters().frames[0] == kFrames);
  CHECK(driver.counters().published == kFrames);
}

TEST_CASE("an image sequence is read through its pattern at the configured rate") {
  TempDir dir;
  for (int i = 0; i < 4; ++i) {
    REQUIRE(cv::imwrite(dir / cv::format("frame_%04d.png", i), cv::Mat(kH, kW, CV_8UC1, cv::Scalar(40 * i + 3))));
  }
  CameraOptions o = file_options();
  o.fps = 10.0;  // a sequence has no rate of its own
  CameraDriver driver(o, {file_opener(dir / "frame_%04d.png")}, no_clock, quiet);
  const std::vector<OutputFrame> frames = run_to_end(driver);
  REQUIRE(frames.size() == 4);
  for (int i = 0; i < 4; ++i) {
    CHECK(frames[static_cast<std::size_t>(i)].utime == 100'000 * i);
    CHECK(frames[static_cast<std::size_t>(i)].left.at<uint8_t>(5, 5) == 40 * i + 3);
  }
  o.fps = 0.0;
  CHECK(error_of([&] {
          CameraDriver(o, {file_opener(dir / "frame_%04d.png")}, no_clock, quiet);
        }).find("no frame rate") != std::string::npos);
}

TEST_CASE("host stamps: capture time minus latency, never backwards") {
  FakeClock clock;
  // Arrival times; the fourth repeats the third (a clock step), the fifth
  // goes back: both dropped and counted.
  const std::vector<int64_t> times = {1'000'000, 1'050'000, 1'100'000, 1'100'000, 1'090'000, 1'200'000};
  CameraOptions o = file_options();
  o.file_timestamps = TimestampMode::kHost;
  o.latency_s = 0.012;
  CameraDriver driver(
      o, {[&] {
        return std::make_unique<ScriptedSource>(&clock, times, std::vector<int>{0, 1, 2, 3, 4, 5}, true);
      }},
      [&] { return clock.now; }, quiet);
  CHECK_FALSE(driver.deterministic());
  const std::vector<OutputFrame> frames = run_to_end(driver);
  REQUIRE(frames.size() == 4);
  const int64_t expected[] = {988'000, 1'038'000, 1'088'000, 1'188'000};
  const int levels[] = {0, 1, 2, 5};
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(frames[i].utime == expected[i]);
    CHECK(frames[i].left.at<uint8_t>(0, 0) == levels[i]);
  }
  CHECK(driver.counters().non_increasing[0] == 2);
  CHECK(driver.counters().frames[0] == 6);
}

TEST_CASE("FrameClock: file-rate stamps from the index, host stamps less the latency") {
  FrameClock file(TimestampMode::kFileRate, 999, 1'000'000, 30.0);
  std::vector<int64_t> stamps;
  for (int i = 0; i < 301; ++i) stamps.push_back(*file.stamp(0));
  CHECK(stamps[1] == 1'033'333);
  CHECK(stamps[2] == 1'066'667);
  CHECK(stamps[300] == 11'000'000);  // no rounding drift over 10 s
  FrameClock host(TimestampMode::kHost, 8000, 0, 0.0);
  CHECK(*host.stamp(20'000) == 12'000);
  CHECK_FALSE(host.stamp(20'000));
  CHECK(*host.stamp(20'001) == 12'001);
  CHECK(host.non_increasing() == 1);
  CHECK_THROWS_AS(FrameClock(TimestampMode::kFileRate, 0, 0, 0.0), std::invalid_argument);
}

TEST_CASE("stereo: frames paired within the tolerance, a dropped frame leaves its partner unpaired") {
  FakeClock clock;
  constexpr int kFrames = 10;
  std::vector<int64_t> left_times, right_times;
  std::vector<int> left_levels, right_levels;
  for (int k = 0; k < kFrames; ++k) {
    left_times.push_back(2'000'000 + 50'000 * k);
    left_levels.push_back(10 * k);
    if (k == 4) continue;                                   // the right camera drops frame 4
    right_times.push_back(2'000'000 + 50'000 * k + 3'000);  // 3 ms behind the left
    right_levels.push_back(10 * k + 1);
  }
  CameraOptions o = file_options(true);
  o.file_timestamps = TimestampMode::kHost;
  o.latency_s = 0.001;
  o.stereo_tolerance_s = 0.005;
  CameraDriver driver(
      o,
      {[&] { return std::make_unique<ScriptedSource>(&clock, left_times, left_levels, true); },
       [&] { return std::make_unique<ScriptedSource>(&clock, right_times, right_levels, true); }},
      [&] { return clock.now; }, quiet);
  const std::vector<OutputFrame> pairs = run_to_end(driver);
  REQUIRE(pairs.size() == kFrames - 1);
  std::size_t p = 0;
  for (int k = 0; k < kFrames; ++k) {
    if (k == 4) continue;
    INFO("frame " << k);
    CHECK(pairs[p].utime == 2'000'000 + 50'000 * k - 1'000);  // the left stamp
    CHECK(pairs[p].left.at<uint8_t>(0, 0) == 10 * k);
    CHECK(pairs[p].right.at<uint8_t>(0, 0) == 10 * k + 1);  // the same capture, not a neighbour
    ++p;
  }
  CHECK(driver.counters().unpaired[0] == 1);
  CHECK(driver.counters().unpaired[1] == 0);
  CHECK(driver.counters().published == kFrames - 1);

  SECTION("an offset beyond the tolerance pairs nothing") {
    for (int64_t& t : right_times) t += 5'000;  // 8 ms apart, tolerance 5 ms
    CameraDriver apart(
        o,
        {[&] { return std::make_unique<ScriptedSource>(&clock, left_times, left_levels, true); },
         [&] { return std::make_unique<ScriptedSource>(&clock, right_times, right_levels, true); }},
        [&] { return clock.now; }, quiet);
    CHECK(run_to_end(apart).empty());
    CHECK(apart.counters().unpaired[0] == kFrames);
    CHECK(apart.counters().unpaired[1] == kFrames - 2);  // 9 right frames, the last still waiting at the end
  }
}

TEST_CASE("StereoPairer: a camera that delivers alone keeps at most max_waiting frames") {
  StereoPairer pairer(5'000, 3);
  for (int k = 0; k < 10; ++k) pairer.add(0, StampedFrame{100'000 * k, cv::Mat()});
  CHECK_FALSE(pairer.next());
  CHECK(pairer.unpaired(0) == 7);
  pairer.add(1, StampedFrame{900'000 + 4'000, cv::Mat()});  // pairs with the newest left
  const std::optional<StereoPair> pair = pairer.next();
  REQUIRE(pair);
  CHECK(pair->utime == 900'000);
  CHECK(pairer.unpaired(0) == 9);
  pairer.add(1, StampedFrame{1'000'000, cv::Mat()});
  CHECK_THROWS_AS(pairer.add(1, StampedFrame{1'000'000, cv::Mat()}), std::invalid_argument);
}

TEST_CASE("a device that stops delivering is reopened with a doubling back-off, stamps keep increasing") {
  FakeClock clock{1'000'000};
  int opens = 0;
  // Open 1 (start): 3 frames, then stalls. Open 2 fails. Open 3: 2 frames.
  SourceOpener opener = [&]() -> std::unique_ptr<FrameSource> {
    ++opens;
    if (opens == 2) throw CameraError("camera left: device /dev/video7 does not exist");
    const int64_t t0 = clock.now;
    std::vector<int64_t> times;
    for (int k = 1; k <= (opens == 1 ? 3 : 2); ++k) times.push_back(t0 + 50'000 * k);
    return std::make_unique<ScriptedSource>(&clock, times, std::vector<int>(times.size(), opens), false);
  };
  CameraOptions o = file_options();
  o.reopen_initial_s = 0.5;
  o.reopen_max_s = 8.0;
  std::vector<std::string> notices;
  CameraDriver driver(
      o, {opener}, [&] { return clock.now; }, [&](const std::string& s) { notices.push_back(s); });
  CHECK_FALSE(driver.deterministic());
  std::vector<OutputFrame> frames;
  const auto step = [&] {
    for (OutputFrame& f : driver.step()) frames.push_back(std::move(f));
  };
  for (int i = 0; i < 4; ++i) step();  // three frames, then the stall at t = 1.15 s
  CHECK(frames.size() == 3);
  CHECK(driver.counters().stalls == 1);
  CHECK(driver.reopening());
  clock.now = 1'150'000 + 499'000;
  step();
  CHECK(opens == 1);  // not before the first interval
  clock.now = 1'150'000 + 500'000;
  step();  // the second open fails: the interval doubles to 1 s
  CHECK(opens == 2);
  CHECK(driver.counters().reopen_failures == 1);
  clock.now = 1'650'000 + 999'000;
  step();
  CHECK(opens == 2);
  clock.now = 1'650'000 + 1'000'000;
  step();  // opens and reads the first new frame
  CHECK(opens == 3);
  CHECK(driver.counters().reopens == 1);
  step();
  CHECK_FALSE(driver.finished());  // a device never finishes
  REQUIRE(frames.size() == 5);
  for (std::size_t i = 1; i < frames.size(); ++i) CHECK(frames[i].utime > frames[i - 1].utime);
  CHECK(frames[3].left.at<uint8_t>(0, 0) == 3);
  REQUIRE(notices.size() == 3);  // the stall, the failed attempt, the reopen
  CHECK(notices[0].find("camera left: device stopped delivering; reopening in 0.5 s") != std::string::npos);
  CHECK(notices[1].find("/dev/video7 does not exist; next attempt in 1 s") != std::string::npos);
  CHECK(notices[2] == "camera left: reopened");
}

TEST_CASE("grey conversion of BGR, BGRA and grey frames; wrong size and type") {
  const cv::Mat bgr(kH, kW, CV_8UC3, frame_colour(3));
  CHECK(to_grey(bgr, kW, kH, false, "left").at<uint8_t>(7, 9) == Approx(frame_grey(3)).margin(1));
  cv::Mat bgra(kH, kW, CV_8UC4, cv::Scalar(frame_colour(3)[0], frame_colour(3)[1], frame_colour(3)[2], 17));
  CHECK(to_grey(bgra, kW, kH, false, "left").at<uint8_t>(7, 9) == Approx(frame_grey(3)).margin(1));
  const cv::Mat grey(kH, kW, CV_8UC1, cv::Scalar(77));
  CHECK(to_grey(grey, kW, kH, false, "left").at<uint8_t>(0, 0) == 77);

  const std::string wrong = error_of([&] { to_grey(grey, 32, 24, false, "right"); });
  CHECK(wrong.find("camera right") != std::string::npos);
  CHECK(wrong.find("64x48") != std::string::npos);
  CHECK(wrong.find("32x24") != std::string::npos);
  const cv::Mat scaled = to_grey(grey, 32, 24, true, "right");
  CHECK(scaled.size() == cv::Size(32, 24));
  CHECK(scaled.at<uint8_t>(11, 13) == 77);
  const std::string type = error_of([&] { to_grey(cv::Mat(kH, kW, CV_16UC1), kW, kH, false, "left"); });
  CHECK(type.find("16UC1") != std::string::npos);
}

TEST_CASE("a video of the wrong size: an error naming both sizes, or scaled when asked") {
  TempDir dir;
  const std::string video = dir / "big.avi";
  REQUIRE(test::write_test_video(video, 3, 20.0, 2 * kW, 2 * kH));
  CameraOptions o = file_options();
  CameraDriver strict(o, {file_opener(video)}, no_clock, quiet);
  const std::string msg = error_of([&] { strict.step(); });
  CHECK(msg.find("128x96") != std::string::npos);
  CHECK(msg.find("configured 64x48") != std::string::npos);
  o.resize = true;
  CameraDriver scaling(o, {file_opener(video)}, no_clock, quiet);
  const std::vector<OutputFrame> frames = run_to_end(scaling);
  REQUIRE(frames.size() == 3);
  CHECK(frames[2].left.size() == cv::Size(kW, kH));
  CHECK(frames[2].left.at<uint8_t>(20, 30) == Approx(frame_grey(2)).margin(1));
}

TEST_CASE("missing or unreadable sources are errors naming the camera and the path") {
  TempDir dir;
  const std::string missing = error_of([&] { open_video_source("left", dir / "none.avi", DeviceRequest{}); });
  CHECK(missing.find("camera left: video file " + (dir / "none.avi") + " does not exist") != std::string::npos);
  std::ofstream(dir / "text.avi") << "not a video\n";
  const std::string bad = error_of([&] { open_video_source("right", dir / "text.avi", DeviceRequest{}); });
  CHECK(bad.find("camera right: cannot read " + (dir / "text.avi")) != std::string::npos);
  const std::string folder = error_of([&] { open_video_source("left", dir.path, DeviceRequest{}); });
  CHECK(folder.find("is a directory") != std::string::npos);
  const std::string device = error_of([&] { open_video_source("left", "/dev/video_absent", DeviceRequest{}); });
  CHECK(device.find("camera left: device /dev/video_absent does not exist") != std::string::npos);
  if (!std::filesystem::exists("/dev/video97")) {
    CHECK(error_of([&] {
            open_video_source("left", "97", DeviceRequest{});
          }).find("camera left: device /dev/video97 does not exist") != std::string::npos);
  }
  const std::string not_camera = error_of([&] { open_video_source("right", "/dev/null", DeviceRequest{}); });
  CHECK(not_camera.find("camera right: cannot open device /dev/null as a V4L2 capture device") != std::string::npos);
  const std::string sequence = error_of([&] { open_video_source("left", dir / "frame_%04d.png", DeviceRequest{}); });
  CHECK(sequence.find("no image matches") != std::string::npos);
  CHECK(is_device_spec("/dev/video0"));
  CHECK(is_device_spec("2"));
  CHECK_FALSE(is_device_spec("clip.avi"));
}

TEST_CASE("camera config: the shipped file, relative files, and its checks") {
  const CameraConfig shipped =
      camera_config_from(vimot::Config::load_file(std::string(VIMOT_SOURCE_DIR) + "/config/camera.yaml"));
  CHECK(shipped.driver.stereo);
  CHECK(shipped.sources == std::vector<std::string>{"/dev/video0", "/dev/video1"});
  CHECK(shipped.request.width == 752);
  CHECK(shipped.request.auto_exposure);
  CHECK(shipped.stall_timeout_s == 2);

  const auto read = [](const std::string& text) {
    return camera_config_from(vimot::Config::from_string(text, "/cfg/cam.yaml"));
  };
  const CameraConfig mono = read(
      "mode: mono\nsources: {left: clip.avi}\nimage: {width: 64, height: 48, exposure: 0.004}\n"
      "timing: {latency: 0.01, file_timestamps: host}\n");
  CHECK(mono.sources == std::vector<std::string>{"/cfg/clip.avi"});
  CHECK_FALSE(mono.request.auto_exposure);
  CHECK(mono.request.exposure_s == 0.004);
  CHECK(mono.driver.latency_s == 0.01);
  CHECK(mono.driver.file_timestamps == TimestampMode::kHost);

  const std::string base = "sources: {left: a.avi, right: b.avi}\nimage: {width: 64, height: 48}\n";
  CHECK(error_of([&] {
          read("mode: stereo\n" + base + "timing: {latency: 0.01, stereo_tolerence: 1}\n");
        }).find("timing.stereo_tolerence") != std::string::npos);
  CHECK(error_of([&] { read("mode: mono\n" + base); }).find("sources.right' is given but mode is mono") !=
        std::string::npos);
  CHECK(error_of([&] { read("mode: trinocular\n" + base); }).find("'mode' must be 'mono' or 'stereo'") !=
        std::string::npos);
  CHECK(error_of([&] {
          read("mode: stereo\n" + base + "reopen: {stall_timeout: 0}\n");
        }).find("reopen.stall_timeout' must be >= 1 s") != std::string::npos);
  CHECK(error_of([&] { read("mode: stereo\n" + base + "timing: {latency: -0.01}\n"); }).find("timing.latency") !=
        std::string::npos);
  CHECK(error_of([&] {
          read("mode: stereo\nsources: {left: a.avi, right: b.avi}\nimage: {width: 64, height: 48, exposure: fast}\n");
        }).find("image.exposure") != std::string::npos);
}

TEST_CASE("the EuRoC slice's cameras as image sequences: the player's pairs, pixels and stamps", "[data]") {
  const std::string csv = vimot::test_data_file_or_skip("euroc_v101_micro/mav0/cam0/data.csv", "EuRoC slice");
  if (csv.empty()) return;
  vimot::euroc::PlayerOptions player_options;
  player_options.dataset = csv.substr(0, csv.size() - std::string("/mav0/cam0/data.csv").size());
  vimot::euroc::EurocPlayer player(player_options);
  std::vector<vimot::euroc::StereoFrame> truth;
  while (const auto event = player.next()) {
    if (const auto* frame = std::get_if<vimot::euroc::StereoFrame>(&*event)) truth.push_back(*frame);
  }
  REQUIRE(truth.size() == 95);
  // The slice's frames are exactly 50 ms apart (in µs): an image sequence at
  // 20 Hz from the first pair's time carries the dataset's own stamps.
  TempDir dir;
  for (const char* side : {"left", "right"}) std::filesystem::create_directory(dir / side);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::string name = cv::format("frame_%04d.png", static_cast<int>(i));
    std::filesystem::create_symlink(truth[i].left_path, dir / ("left/" + name));
    std::filesystem::create_symlink(truth[i].right_path, dir / ("right/" + name));
  }
  CameraOptions o = file_options(true);
  o.width = player.summary().width;
  o.height = player.summary().height;
  o.fps = 20.0;
  o.file_start_utime = truth.front().utime;
  CameraDriver driver(o, {file_opener(dir / "left/frame_%04d.png"), file_opener(dir / "right/frame_%04d.png")},
                      no_clock, quiet);
  const std::vector<OutputFrame> pairs = run_to_end(driver);
  REQUIRE(pairs.size() == truth.size());
  for (std::size_t i = 0; i < truth.size(); ++i) {
    INFO("pair " << i);
    CHECK(pairs[i].utime == truth[i].utime);
    const vimot::euroc::StereoImages images = player.load_images(truth[i]);
    CHECK(cv::norm(pairs[i].left, images.left, cv::NORM_INF) == 0.0);
    CHECK(cv::norm(pairs[i].right, images.right, cv::NORM_INF) == 0.0);
  }
  CHECK(driver.counters().unpaired[0] + driver.counters().unpaired[1] == 0);
}

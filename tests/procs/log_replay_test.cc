// vimot-log-replay's comparison (procs/log_replay/log_replay.h) without a
// network: a "live" log is written here the way a run records it — the
// simulator's inputs and, interleaved, the VINS_STATE a VinsNode published
// on them — and replay_log must reproduce every state byte for byte; a state
// the logger lost is counted as not logged, a changed one is a difference.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "common/config/config.h"
#include "common/process/event_sink.h"
#include "common/process/lcm_conversions.h"
#include "common/sim/simulator.h"
#include "procs/log_replay/log_replay.h"
#include "procs/vins/vins_node.h"

using namespace vimot;

namespace {

const std::string kVinsConfig = VIMOT_SOURCE_DIR "/config/vins.yaml";

std::string temp_log(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("log_replay_test_" + std::to_string(::getpid()) + "_" + name);
}

/// 3 s of sim_paper (seed 2) and a VinsNode's states on it; `keep(i, bytes)`
/// decides what the "logger" writes of the i-th state (false: lost). Before
/// state `republish_at`, the `republish` states before it are written again
/// (a process respawned from a checkpoint written before them), the first
/// copy with one bit flipped if `flip_copy`.
void write_live_log(const std::string& path, const std::function<bool(int, std::vector<uint8_t>*)>& keep,
                    int republish_at = -1, int republish = 0, bool flip_copy = false) {
  sim::SimConfig cfg = sim::from_config(Config::load_file(VIMOT_SOURCE_DIR "/config/sim_paper.yaml"));
  cfg.seed = 2;
  cfg.duration = 3.0;
  sim::Simulator sim(cfg);
  LogFileSink log(path);
  int state_index = 0;
  std::vector<std::vector<uint8_t>> written;
  VinsNode node(
      vins_node_options_from_config(Config::load_file(kVinsConfig)),
      [&](const NavState& s) {
        const nav_state_t msg = to_lcm(s);
        std::vector<uint8_t> bytes(static_cast<std::size_t>(msg.getEncodedSize()));
        msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
        if (state_index == republish_at) {
          for (std::size_t k = written.size() - static_cast<std::size_t>(republish); k < written.size(); ++k) {
            std::vector<uint8_t> copy = written[k];
            if (flip_copy && k + static_cast<std::size_t>(republish) == written.size()) copy.back() ^= 1;
            log.write("VINS_STATE", msg.utime, copy.data(), static_cast<int>(copy.size()));
          }
        }
        if (keep(state_index++, &bytes)) {
          log.write("VINS_STATE", msg.utime, bytes.data(), static_cast<int>(bytes.size()));
          written.push_back(bytes);
        }
      },
      [](const NodeEvent&) {});
  while (const auto event = sim.next()) {
    if (const auto* imu = std::get_if<ImuData>(&*event)) {
      emit(log, "IMU", to_lcm(*imu));
      node.on_imu(*imu);
    } else if (const auto* frame = std::get_if<CameraFrame>(&*event)) {
      emit(log, "FEATURES", to_lcm(*frame));
      node.on_frame(*frame);
    } else if (const auto* truth = std::get_if<GroundTruth>(&*event)) {
      emit(log, "GROUND_TRUTH", to_lcm(*truth));
      node.on_ground_truth(*truth);
    }
  }
  node.flush();
}

ChannelComparison replay(const std::string& path) {
  ReplaySetup setup;
  setup.vins_config = kVinsConfig;
  const ReplayReport report = replay_log(path, setup);
  std::filesystem::remove(path);
  REQUIRE(report.channels.size() == 1);
  REQUIRE(report.channels[0].channel == "VINS_STATE");
  return report.channels[0];
}

}  // namespace

TEST_CASE("replay_log reproduces a recorded VinsNode's states byte for byte") {
  const std::string path = temp_log("all");
  write_live_log(path, [](int, std::vector<uint8_t>*) { return true; });
  const ChannelComparison c = replay(path);
  // 3 s: 31 frames (updated states) and an IMU-rate state every 10th sample.
  CHECK(c.recorded >= 31 + 59);
  CHECK(c.equal());
  CHECK(c.identical == c.recorded);
  CHECK(c.replayed == c.recorded);
  CHECK(c.not_logged == 0);
}

TEST_CASE("replay_log counts states the logger lost and finds a changed one") {
  const std::string lost = temp_log("lost");
  write_live_log(lost, [](int i, std::vector<uint8_t>*) { return i != 10 && i != 11; });
  const ChannelComparison l = replay(lost);
  CHECK(l.equal());
  CHECK(l.not_logged == 2);
  CHECK(l.replayed == l.recorded + 2);
  CHECK(l.identical == l.recorded);

  const std::string changed = temp_log("changed");
  write_live_log(changed, [](int i, std::vector<uint8_t>* bytes) {
    if (i == 20) bytes->back() ^= 1;  // one bit of the last covariance entry
    return true;
  });
  const ChannelComparison d = replay(changed);
  CHECK_FALSE(d.equal());
  CHECK(d.first_difference == 20);
  CHECK(d.identical == 20);
  CHECK(d.first_difference_utime > 0);
}

TEST_CASE("replay_log takes the states a respawned process published again as republished copies") {
  const std::string again = temp_log("again");
  write_live_log(again, [](int, std::vector<uint8_t>*) { return true; }, 40, 6);
  const ChannelComparison r = replay(again);
  CHECK(r.equal());
  CHECK(r.republished == 6);
  CHECK(r.identical == r.replayed);
  CHECK(r.recorded == r.replayed + 6);
  CHECK(r.not_logged == 0);

  const std::string changed = temp_log("again_changed");
  write_live_log(changed, [](int, std::vector<uint8_t>*) { return true; }, 40, 6, /*flip_copy=*/true);
  const ChannelComparison d = replay(changed);
  CHECK_FALSE(d.equal());
  CHECK(d.first_difference == 40);  // the copy of state 34, recorded after the first 40
  CHECK(d.republished == 0);
}

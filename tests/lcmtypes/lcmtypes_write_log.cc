// Writes one sample of every vimot message, on its channel from
// docs/channels.md, into an LCM log. The Java check decodes that log the way
// lcm-spy does; the log is also handy to look at every type by hand:
//   lcm-logplayer-gui <log> & scripts/lcm-spy.sh
#include <lcm/lcm-cpp.hpp>

#include <cstdio>
#include <string>
#include <vector>

#include "lcmtypes_samples.h"

namespace {

class Writer {
 public:
  explicit Writer(const std::string& path) : log_(path, "w") {}
  bool good() const { return log_.good(); }

  template <typename Msg>
  bool write(const std::string& channel, const Msg& msg) {
    std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
    if (msg.encode(buf.data(), 0, static_cast<int>(buf.size())) < 0) return false;
    lcm::LogEvent ev{};
    ev.timestamp = msg.utime;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(buf.size());
    ev.data = buf.data();
    ++count_;
    return log_.writeEvent(&ev) == 0;
  }
  int count() const { return count_; }

 private:
  lcm::LogFile log_;
  int count_{0};
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <output.lcmlog>\n", argv[0]);
    return 2;
  }
  Writer w(argv[1]);
  if (!w.good()) {
    std::fprintf(stderr, "cannot open %s for writing\n", argv[1]);
    return 1;
  }
  namespace t = vimot_test;
  const bool ok = w.write("IMU", t::sample_imu()) &&
                  w.write("CAM_LEFT", t::sample_image()) &&
                  w.write("FEATURES", t::sample_features()) &&
                  w.write("TARGET_MASK", t::sample_mask()) &&
                  w.write("TARGET_BOX", t::sample_target_box()) &&
                  w.write("VINS_STATE", t::sample_nav_state()) &&
                  w.write("TARGET_STATE", t::sample_target_state()) &&
                  w.write("TARGET_PREDICTION", t::sample_target_prediction()) &&
                  w.write("OBJECT_POSE_UPTOSCALE", t::sample_object_pose()) &&
                  w.write("SCALE_ESTIMATE", t::sample_scale_estimate()) &&
                  w.write("OBJECT_POSE_METRIC", t::sample_metric_object_pose()) &&
                  w.write("OBJECT_STATE", t::sample_target_state()) &&
                  w.write("OBJECT_PREDICTION", t::sample_target_prediction()) &&
                  w.write("GROUND_TRUTH", t::sample_ground_truth()) &&
                  w.write("HEARTBEAT", t::sample_heartbeat());
  if (!ok) {
    std::fprintf(stderr, "failed writing %s\n", argv[1]);
    return 1;
  }
  std::printf("%d\n", w.count());
  return 0;
}

#include "common/process/log_reader.h"

#include <lcm/lcm-cpp.hpp>
#include <stdexcept>
#include <utility>

#include "common/process/lcm_conversions.h"
#include "common/process/lcm_type_registry.h"

namespace vimot {

struct LogReader::Log {
  explicit Log(const std::string& path) : file(path, "r") {}
  lcm::LogFile file;
};


LogReader::LogReader(const std::string& path) : log_(std::make_unique<Log>(path)) {
  if (!log_->file.good()) throw std::runtime_error("cannot open LCM log '" + path + "'");
}

LogReader::~LogReader() = default;

template <typename Msg, typename Plain>
void LogReader::subscribe(const std::string& channel, std::function<void(const Plain&)> use, int64_t* malformed) {
  if (channel.empty()) return;
  // Decodes as Msg, converts (from_lcm throws std::invalid_argument on
  // non-finite numbers or bad counts) and delivers; else counts.
  handlers_.emplace(channel, [this, use = std::move(use), malformed](const void* data, int size, int64_t eventnum,
                                                                      const std::string& ch) {
    Msg msg;
    std::string why = "does not decode as " + std::string(Msg::getTypeName());
    if (decode_untrusted(data, size, &msg)) {
      try {
        use(from_lcm(msg));
        return;
      } catch (const std::invalid_argument& e) {
        why = e.what();
      }
    }
    ++*malformed;
    if (first_malformed_.empty()) first_malformed_ = "event " + std::to_string(eventnum) + " on " + ch + ": " + why;
  });
}

void LogReader::on_nav_state(const std::string& channel, std::function<void(const NavState&)> use,
                             int64_t* malformed) {
  subscribe<nav_state_t>(channel, std::move(use), malformed);
}

void LogReader::on_ground_truth(const std::string& channel, std::function<void(const GroundTruth&)> use,
                                int64_t* malformed) {
  subscribe<ground_truth_t>(channel, std::move(use), malformed);
}

void LogReader::on_target_state(const std::string& channel, std::function<void(const TargetStateEstimate&)> use,
                                int64_t* malformed) {
  subscribe<target_state_t>(channel, std::move(use), malformed);
}

void LogReader::on_scale_estimate(const std::string& channel, std::function<void(const scale::ScaleResult&)> use,
                                  int64_t* malformed) {
  subscribe<scale_estimate_t>(channel, std::move(use), malformed);
}

void LogReader::on_metric_pose(const std::string& channel,
                               std::function<void(const scale::ObjectPoseInWorld&)> use, int64_t* malformed) {
  subscribe<metric_object_pose_t>(channel, std::move(use), malformed);
}

void LogReader::on_target_box(const std::string& channel, std::function<void(const CameraTargetBox&)> use,
                              int64_t* malformed) {
  subscribe<target_box_t>(channel, std::move(use), malformed);
}

void LogReader::on_imu(const std::string& channel, std::function<void(const ImuData&)> use, int64_t* malformed) {
  subscribe<imu_t>(channel, std::move(use), malformed);
}

void LogReader::on_features(const std::string& channel, std::function<void(const CameraFrame&)> use,
                            int64_t* malformed) {
  subscribe<features_t>(channel, std::move(use), malformed);
}

int64_t LogReader::read_all() {
  int64_t events = 0;
  while (read_next()) ++events;
  return events;
}

bool LogReader::read_next() {
  // LCM's reader returns null on a short read: a partial event ends the log.
  const lcm::LogEvent* ev = log_->file.readNextEvent();
  if (ev == nullptr) return false;
  const auto it = handlers_.find(ev->channel);
  if (it != handlers_.end()) it->second(ev->data, ev->datalen, ev->eventnum, ev->channel);
  return true;
}

}  // namespace vimot

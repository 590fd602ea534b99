#include "common/process/catch_up.h"

#include <utility>

namespace vimot {

CatchUpLog::CatchUpLog(const std::string& path, const CatchUpChannels& channels, int64_t from_utime)
    : from_utime_(from_utime), reader_(path) {
  // Queues a decoded message of `input` into `member` of a LoggedInput.
  const auto keep = [this](EstimatorInput input, auto member, const auto& value) {
    if (value.utime < from_utime_) return;
    LoggedInput m;
    m.input = input;
    m.utime = value.utime;
    m.*member = value;
    ready_.push_back(std::move(m));
  };
  reader_.on_imu(
      channels.imu, [keep](const ImuData& v) { keep(EstimatorInput::kImu, &LoggedInput::imu, v); }, &malformed_);
  reader_.on_features(
      channels.features, [keep](const CameraFrame& v) { keep(EstimatorInput::kFrame, &LoggedInput::frame, v); },
      &malformed_);
  reader_.on_ground_truth(
      channels.ground_truth,
      [keep](const GroundTruth& v) { keep(EstimatorInput::kGroundTruth, &LoggedInput::truth, v); }, &malformed_);
}

bool CatchUpLog::next(LoggedInput* out) {
  while (ready_.empty()) {
    if (!reader_.read_next()) return false;
  }
  *out = std::move(ready_.front());
  ready_.pop_front();
  return true;
}

}  // namespace vimot

#pragma once
// A respawned estimator's missed input, read back from the run's flight
// recorder (vimot-logger's LCM log, flushed per message): the messages of
// its input channels in the order the logger received them, decoded as the
// Node's inputs (docs/sheriff.md, "Recovery"). Built on LogReader, so no LCM
// type is visible here. A malformed message is counted and skipped; a
// partial last event (the logger mid-write) ends the log.

#include <cstdint>
#include <deque>
#include <string>

#include "common/process/log_reader.h"
#include "common/process/node_event.h"
#include "common/types/ground_truth.h"
#include "common/types/sensor_data.h"

namespace vimot {

/// The Node's input channels (an empty one is not read).
struct CatchUpChannels {
  std::string imu{"IMU"};
  std::string features{"FEATURES"};
  std::string ground_truth{"GROUND_TRUTH"};
};

/// One logged input message; only the member of `input` is set.
struct LoggedInput {
  EstimatorInput input{EstimatorInput::kImu};
  int64_t utime{0};
  ImuData imu;
  CameraFrame frame;
  GroundTruth truth;
};

class CatchUpLog {
 public:
  /// Messages with utime >= from_utime. Throws std::runtime_error (naming
  /// the file) if the log cannot be opened.
  CatchUpLog(const std::string& path, const CatchUpChannels& channels, int64_t from_utime);
  CatchUpLog(const CatchUpLog&) = delete;
  CatchUpLog& operator=(const CatchUpLog&) = delete;

  /// The next input message in log order; false at the end of the log.
  bool next(LoggedInput* out);
  /// Messages that did not decode or convert, and the first one's description.
  int64_t malformed() const { return malformed_; }
  const std::string& first_malformed() const { return reader_.first_malformed(); }

 private:
  int64_t from_utime_;
  LogReader reader_;
  std::deque<LoggedInput> ready_;  // what the last read event delivered (one message)
  int64_t malformed_{0};
};

}  // namespace vimot

#pragma once
// Reads an LCM log (lcm-logger, vimot-sim --log) into plain vimot types: the
// log-file twin of Process::subscribe, so offline tools (vimot-log-eval's
// common/eval/log_eval.h) see no LCM type. A message that does not decode or
// convert (common/process/lcm_conversions.h) is counted and skipped, never
// fatal. The LCM is in log_reader.cc only.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>

#include "common/object/scale_estimator.h"
#include "common/types/ground_truth.h"
#include "common/types/nav_state.h"
#include "common/types/sensor_data.h"
#include "common/types/target_box.h"
#include "common/types/target_state.h"

namespace vimot {

class LogReader {
 public:
  /// Throws std::runtime_error if the log cannot be opened.
  explicit LogReader(const std::string& path);
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  /// Messages on `channel` are decoded as the type of `use`'s argument and
  /// handed to it; a malformed one increments *malformed. A channel keeps
  /// its first handler (a later one for the same channel is ignored). An
  /// empty channel subscribes nothing.
  void on_nav_state(const std::string& channel, std::function<void(const NavState&)> use, int64_t* malformed);
  void on_ground_truth(const std::string& channel, std::function<void(const GroundTruth&)> use,
                       int64_t* malformed);
  void on_target_state(const std::string& channel, std::function<void(const TargetStateEstimate&)> use,
                       int64_t* malformed);
  void on_scale_estimate(const std::string& channel, std::function<void(const scale::ScaleResult&)> use,
                         int64_t* malformed);
  /// p_OinC is not in the message (left zero).
  void on_metric_pose(const std::string& channel, std::function<void(const scale::ObjectPoseInWorld&)> use,
                      int64_t* malformed);

  void on_target_box(const std::string& channel, std::function<void(const CameraTargetBox&)> use,
                     int64_t* malformed);
  void on_imu(const std::string& channel, std::function<void(const ImuData&)> use, int64_t* malformed);
  void on_features(const std::string& channel, std::function<void(const CameraFrame&)> use, int64_t* malformed);

  /// Reads every event in order; returns how many there were.
  int64_t read_all();
  /// Reads the next event and hands it to its channel's handler; false at
  /// the end of the log. A partial last event (its writer is mid-write) is
  /// the end.
  bool read_next();
  /// "event <n> on <channel>: <why>" of the first malformed message, or empty.
  const std::string& first_malformed() const { return first_malformed_; }

 private:
  struct Log;
  using Handler = std::function<void(const void* data, int size, int64_t eventnum, const std::string& channel)>;
  /// Msg: the LCM type on the channel (log_reader.cc only).
  template <typename Msg, typename Plain>
  void subscribe(const std::string& channel, std::function<void(const Plain&)> use, int64_t* malformed);

  std::unique_ptr<Log> log_;
  std::map<std::string, Handler> handlers_;
  std::string first_malformed_;
};

}  // namespace vimot

#pragma once
// The MIP IMU driver without LCM: opens the byte stream, sets the device up,
// turns its packets into ImuData on the host clock, and recovers from
// everything a serial link does (garbage, lost bytes, unplugging).
//
// Start-up (each command waits for its ACK/NACK, retried on timeout):
//   idle (0x01,0x02) -> IMU base rate (0x0C,0x06) -> IMU message format
//   (0x0C,0x08: scaled accel, scaled gyro, timestamp at base/decimation) ->
//   enable IMU stream (0x0C,0x11) -> resume (0x01,0x06).
// A NACK or a command unanswered after its tries fails the set-up; the
// stream is closed and reopened after `reconnect_interval`. A hang-up, a
// read error, or no IMU sample for `stream_timeout` while streaming does the
// same (a device that reset comes back idle and must be set up again).

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/types/sensor_data.h"
#include "drivers/imu_mip/byte_stream.h"
#include "drivers/imu_mip/device_time_mapper.h"
#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"

namespace vimot::mip {

struct ImuMipOptions {
  double rate_hz{200.0};              // requested IMU rate; the device divides its base rate
  uint8_t timestamp_field{kFieldGpsTimestamp};  // 0x12 (3DM-GX4) or 0xD5 (newer devices)
  double command_timeout{0.3};        // s to wait for each command's ACK/NACK
  int command_tries{3};               // sends per command before the set-up fails
  double reconnect_interval{1.0};     // s between attempts to open and set up
  double stream_timeout{1.0};         // s without an IMU sample before the link counts as lost
  DeviceTimeMapperOptions time;
};

/// Everything that happened to the byte stream, cumulative over reconnects.
struct ImuMipCounters {
  int64_t samples{0};               // IMU samples emitted
  int64_t bytes_in{0};
  int64_t packets{0};               // checksum-valid packets, of any kind
  int64_t bytes_dropped{0};         // bytes in no accepted packet (garbage, broken frames, partial at a hang-up)
  int64_t packets_dropped{0};       // checksum errors + malformed frames + malformed IMU packets
  int64_t checksum_errors{0};
  int64_t malformed_samples{0};     // valid frames with IMU fields of the wrong size or non-finite
  int64_t packets_ignored{0};       // valid packets not used: other data, replies to nothing, data during set-up
  int64_t samples_without_device_time{0};  // stamped with their arrival time
  int64_t nacks{0};
  int64_t command_timeouts{0};      // unanswered command sends
  int64_t setup_failures{0};
  int64_t disconnects{0};           // links lost while streaming
  int64_t reconnects{0};            // set-ups completed after the first
  int64_t time_relocks{0};          // device clock restarts / host clock steps
};

/// The counters as (snake_case name, value) for the heartbeat, in a fixed order.
std::vector<std::pair<std::string, int64_t>> named_counters(const ImuMipCounters& c);

class ImuMipDriver {
 public:
  using SampleCallback = std::function<void(const ImuData&)>;
  /// Log lines: `error` true for problems (counted by the process).
  using EventCallback = std::function<void(const std::string& message, bool error)>;
  /// Host time now, µs (the wall clock in the process; injectable in tests).
  using HostClock = std::function<int64_t()>;

  ImuMipDriver(const ImuMipOptions& options, StreamOpener opener, SampleCallback on_sample, EventCallback on_event,
               HostClock clock);

  /// One step, at most about `wait_ms` plus a set-up: opens and sets up the
  /// device when there is no stream (rate-limited by reconnect_interval),
  /// otherwise reads what arrived and emits the samples.
  void step(int wait_ms = 50);

  bool streaming() const { return stream_ != nullptr; }
  /// The IMU rate the device was set to (base rate / decimation), 0 before set-up.
  double device_rate_hz() const { return device_rate_hz_; }
  ImuMipCounters counters() const;

 private:
  using SteadyClock = std::chrono::steady_clock;

  void connect();
  void setup();
  /// Sends a command and waits for its ACK; returns the reply packet.
  MipPacket command(const std::vector<uint8_t>& bytes, uint8_t descriptor_set, uint8_t cmd, const char* what);
  void read_available(int wait_ms);
  void handle_packet(const MipPacket& packet, int64_t arrival_utime);
  void lose_stream(const std::string& why);

  ImuMipOptions options_;
  StreamOpener opener_;
  SampleCallback on_sample_;
  EventCallback on_event_;
  HostClock clock_;

  std::unique_ptr<ByteStream> stream_;
  MipParser parser_;
  DeviceTimeMapper time_mapper_;
  ImuMipCounters counters_;
  double device_rate_hz_{0.0};
  bool ever_streamed_{false};
  bool open_failure_logged_{false};
  int64_t last_utime_{0};
  int64_t malformed_logged_{0};
  SteadyClock::time_point next_attempt_{};
  SteadyClock::time_point last_sample_{};
  std::vector<uint8_t> read_buffer_;
};

}  // namespace vimot::mip

#include "drivers/imu_mip/imu_mip_driver.h"

#include <algorithm>
#include <cmath>
#include <thread>

namespace vimot::mip {

namespace {

// A set-up step the device refused or never answered.
class SetupError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Malformed IMU packets are logged for the first few, then only counted.
constexpr int64_t kMaxMalformedLogged = 10;

int to_ms(double seconds) { return static_cast<int>(std::lround(seconds * 1000.0)); }

}  // namespace

std::vector<std::pair<std::string, int64_t>> named_counters(const ImuMipCounters& c) {
  return {{"samples", c.samples},
          {"bytes_in", c.bytes_in},
          {"packets", c.packets},
          {"bytes_dropped", c.bytes_dropped},
          {"packets_dropped", c.packets_dropped},
          {"checksum_errors", c.checksum_errors},
          {"malformed_samples", c.malformed_samples},
          {"packets_ignored", c.packets_ignored},
          {"samples_without_device_time", c.samples_without_device_time},
          {"nacks", c.nacks},
          {"command_timeouts", c.command_timeouts},
          {"setup_failures", c.setup_failures},
          {"disconnects", c.disconnects},
          {"reconnects", c.reconnects},
          {"time_relocks", c.time_relocks}};
}

ImuMipDriver::ImuMipDriver(const ImuMipOptions& options, StreamOpener opener, SampleCallback on_sample,
                           EventCallback on_event, HostClock clock)
    : options_(options),
      opener_(std::move(opener)),
      on_sample_(std::move(on_sample)),
      on_event_(std::move(on_event)),
      clock_(std::move(clock)),
      time_mapper_(options.time),
      read_buffer_(4096) {
  if (!(options.rate_hz > 0.0) || !(options.command_timeout > 0.0) || options.command_tries < 1 ||
      !(options.reconnect_interval >= 0.0) || !(options.stream_timeout > 0.0)) {
    throw std::invalid_argument(
        "ImuMipDriver: rate_hz, command_timeout, stream_timeout must be > 0, command_tries >= 1, "
        "reconnect_interval >= 0");
  }
  if (options.stream_timeout < 2.0 / options.rate_hz) {
    throw std::invalid_argument("ImuMipDriver: stream_timeout " + std::to_string(options.stream_timeout) +
                                " s is under two sample periods at " + std::to_string(options.rate_hz) + " Hz");
  }
  if (options.timestamp_field != kFieldGpsTimestamp && options.timestamp_field != kFieldReferenceTime) {
    throw std::invalid_argument("ImuMipDriver: timestamp_field must be 0x12 (GPS correlation) or 0xD5 (reference)");
  }
}

ImuMipCounters ImuMipDriver::counters() const {
  ImuMipCounters c = counters_;
  const MipParserCounters& p = parser_.counters();
  c.bytes_in = p.bytes_in;
  c.packets = p.packets;
  c.bytes_dropped = p.bytes_dropped;
  c.checksum_errors = p.checksum_errors;
  c.packets_dropped = p.packets_dropped() + counters_.malformed_samples;
  c.time_relocks = time_mapper_.relocks();
  return c;
}

void ImuMipDriver::step(int wait_ms) {
  if (!stream_) {
    const auto now = SteadyClock::now();
    if (now < next_attempt_) {
      // Not yet time to retry: wait here, not in a busy loop of the caller.
      std::this_thread::sleep_for(std::min<SteadyClock::duration>(next_attempt_ - now,
                                                                   std::chrono::milliseconds(wait_ms)));
      return;
    }
    connect();
    return;
  }
  try {
    read_available(wait_ms);
  } catch (const StreamClosed& e) {
    lose_stream(e.what());
    return;
  }
  if (SteadyClock::now() - last_sample_ > std::chrono::milliseconds(to_ms(options_.stream_timeout))) {
    lose_stream("no IMU sample for " + std::to_string(options_.stream_timeout) + " s");
  }
}

void ImuMipDriver::connect() {
  next_attempt_ = SteadyClock::now() + std::chrono::milliseconds(to_ms(options_.reconnect_interval));
  try {
    stream_ = opener_();
  } catch (const std::exception& e) {
    // An absent device is the normal state while unplugged: said once.
    if (!open_failure_logged_) on_event_(std::string("cannot open the IMU: ") + e.what() + " (retrying)", true);
    open_failure_logged_ = true;
    return;
  }
  open_failure_logged_ = false;
  parser_.reset();
  try {
    setup();
  } catch (const std::exception& e) {
    ++counters_.setup_failures;
    on_event_(std::string("IMU set-up failed: ") + e.what(), true);
    stream_.reset();
    return;
  }
  time_mapper_.reset();
  last_sample_ = SteadyClock::now();
  if (ever_streamed_) ++counters_.reconnects;
  ever_streamed_ = true;
  on_event_("IMU streaming at " + std::to_string(device_rate_hz_) + " Hz", false);
}

MipPacket ImuMipDriver::command(const std::vector<uint8_t>& bytes, uint8_t descriptor_set, uint8_t cmd,
                                const char* what) {
  MipPacket packet;
  for (int attempt = 0; attempt < options_.command_tries; ++attempt) {
    stream_->write(bytes.data(), bytes.size(), to_ms(options_.command_timeout));
    const auto deadline = SteadyClock::now() + std::chrono::milliseconds(to_ms(options_.command_timeout));
    for (;;) {
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - SteadyClock::now()).count();
      if (left <= 0) break;
      const std::size_t n = stream_->read(read_buffer_.data(), read_buffer_.size(), static_cast<int>(left));
      parser_.feed(read_buffer_.data(), n);
      while (parser_.next(packet)) {
        const std::optional<MipAck> ack = find_ack(packet, descriptor_set, cmd);
        if (!ack) {
          ++counters_.packets_ignored;  // data still streaming before idle, stale replies
          continue;
        }
        if (!ack->ok()) {
          ++counters_.nacks;
          throw SetupError(std::string(what) + ": NACK (" + nack_name(ack->error) + ")");
        }
        return packet;
      }
    }
    ++counters_.command_timeouts;
  }
  throw SetupError(std::string(what) + ": no reply after " + std::to_string(options_.command_tries) + " tries of " +
                   std::to_string(options_.command_timeout) + " s");
}

void ImuMipDriver::setup() {
  command(command_idle(), kBaseCommandSet, kCmdIdle, "idle");
  const MipPacket reply = command(command_get_imu_base_rate(), k3dmCommandSet, kCmdGetImuBaseRate, "IMU base rate");
  const std::optional<uint16_t> base_rate = find_imu_base_rate(reply);
  if (!base_rate || *base_rate == 0) throw SetupError("IMU base rate: reply without a valid rate");
  const double decimation = std::clamp(std::round(*base_rate / options_.rate_hz), 1.0, 65535.0);
  device_rate_hz_ = *base_rate / decimation;
  if (std::abs(device_rate_hz_ - options_.rate_hz) > 0.01 * options_.rate_hz) {
    on_event_("IMU rate " + std::to_string(options_.rate_hz) + " Hz is not a divisor of the base rate " +
                  std::to_string(*base_rate) + " Hz; using " + std::to_string(device_rate_hz_) + " Hz",
              false);
  }
  command(command_imu_message_format({kFieldScaledAccel, kFieldScaledGyro, options_.timestamp_field},
                                     static_cast<uint16_t>(decimation)),
          k3dmCommandSet, kCmdImuMessageFormat, "IMU message format");
  command(command_enable_imu_stream(true), k3dmCommandSet, kCmdEnableDataStream, "enable IMU stream");
  command(command_resume(), kBaseCommandSet, kCmdResume, "resume");
}

void ImuMipDriver::read_available(int wait_ms) {
  const std::size_t n = stream_->read(read_buffer_.data(), read_buffer_.size(), wait_ms);
  if (n == 0) return;
  const int64_t arrival = clock_();
  parser_.feed(read_buffer_.data(), n);
  MipPacket packet;
  while (parser_.next(packet)) handle_packet(packet, arrival);
}

void ImuMipDriver::handle_packet(const MipPacket& packet, int64_t arrival_utime) {
  MipImuSample sample;
  std::string why;
  switch (decode_imu(packet, sample, &why)) {
    case ImuDecode::kNotImu:
      ++counters_.packets_ignored;
      return;
    case ImuDecode::kMalformed:
      ++counters_.malformed_samples;
      if (++malformed_logged_ <= kMaxMalformedLogged) {
        on_event_("malformed IMU packet dropped: " + why +
                      (malformed_logged_ == kMaxMalformedLogged ? " (further ones only counted)" : ""),
                  true);
      }
      return;
    case ImuDecode::kSample:
      break;
  }
  ImuData imu;
  if (sample.device_time) {
    imu.utime = time_mapper_.map(*sample.device_time, arrival_utime);
  } else {
    ++counters_.samples_without_device_time;
    imu.utime = arrival_utime;
  }
  // The mapper never goes back on its own; this also covers the arrival-time
  // fallback and a mix of both.
  imu.utime = std::max(imu.utime, last_utime_ + 1);
  last_utime_ = imu.utime;
  imu.a_IinI = sample.a_IinI;
  imu.w_IinI = sample.w_IinI;
  last_sample_ = SteadyClock::now();
  ++counters_.samples;
  on_sample_(imu);
}

void ImuMipDriver::lose_stream(const std::string& why) {
  ++counters_.disconnects;
  on_event_("IMU link lost (" + why + "); reopening", true);
  stream_.reset();
  parser_.reset();
  next_attempt_ = SteadyClock::now();
}

}  // namespace vimot::mip

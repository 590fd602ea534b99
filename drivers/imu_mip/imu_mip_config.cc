#include "drivers/imu_mip/imu_mip_config.h"

namespace vimot::mip {

ImuMipConfig imu_mip_config_from(const Config& config) {
  ImuMipConfig c;
  const Config device = config.sub("device");
  c.port = device.get<std::string>("port");
  c.baud = device.get_or<int>("baud", c.baud);
  if (c.baud <= 0) device.fail("baud", "must be > 0, got " + std::to_string(c.baud));
  const std::string interface = device.get_or<std::string>("interface", "serialport");
  if (interface != "serialport" && interface != "tty") {
    device.fail("interface", "must be 'serialport' or 'tty', got '" + interface + "'");
  }
  c.raw_tty = interface == "tty";

  ImuMipOptions& o = c.driver;
  o.rate_hz = device.get_or<double>("rate", o.rate_hz);
  if (o.rate_hz <= 0.0) device.fail("rate", "must be > 0 Hz");
  const std::string stamp = device.get_or<std::string>("timestamp", "gps");
  if (stamp != "gps" && stamp != "reference") {
    device.fail("timestamp", "must be 'gps' (0x80,0x12) or 'reference' (0x80,0xD5), got '" + stamp + "'");
  }
  o.timestamp_field = stamp == "gps" ? kFieldGpsTimestamp : kFieldReferenceTime;
  o.command_timeout = device.get_or<double>("command_timeout", o.command_timeout);
  o.command_tries = device.get_or<int>("command_tries", o.command_tries);
  o.reconnect_interval = device.get_or<double>("reconnect_interval", o.reconnect_interval);
  o.stream_timeout = device.get_or<double>("stream_timeout", o.stream_timeout);
  if (o.command_timeout <= 0.0) device.fail("command_timeout", "must be > 0 s");
  if (o.command_tries < 1) device.fail("command_tries", "must be >= 1");
  if (o.reconnect_interval < 0.0) device.fail("reconnect_interval", "must be >= 0 s");
  if (o.stream_timeout <= 0.0) device.fail("stream_timeout", "must be > 0 s");

  if (config.has("time_mapping")) {
    const Config t = config.sub("time_mapping");
    o.time.max_drift = t.get_or<double>("max_drift", o.time.max_drift);
    o.time.relock_threshold = t.get_or<double>("relock_threshold", o.time.relock_threshold);
    o.time.relock_after = t.get_or<double>("relock_after", o.time.relock_after);
    if (o.time.max_drift < 0.0) t.fail("max_drift", "must be >= 0 s/s");
    if (o.time.relock_threshold <= 0.0) t.fail("relock_threshold", "must be > 0 s");
    if (o.time.relock_after <= 0.0) t.fail("relock_after", "must be > 0 s");
  }
  return c;
}

StreamOpener stream_opener(const ImuMipConfig& config) {
  if (config.raw_tty) return [port = config.port, baud = config.baud] { return open_tty_fd(port, baud); };
  return [port = config.port, baud = config.baud] { return open_serial_port(port, baud); };
}

}  // namespace vimot::mip

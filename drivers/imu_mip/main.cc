// vimot-imu-mip: a LORD MicroStrain MIP IMU (3DM-GX4 family) on a serial
// port, published as IMU (imu_t) on the host clock. The protocol, set-up,
// reconnects and time mapping are ImuMipDriver (no LCM); this file converts
// and reports.
#include <chrono>

#include "common/process/lcm_conversions.h"
#include "common/process/process.h"
#include "common/time/utime.h"
#include "drivers/imu_mip/imu_mip_config.h"

namespace {

void report_counters(vimot::Process& process, const vimot::mip::ImuMipCounters& c) {
  process.counters().messages_in = c.packets;
  process.counters().dropped = c.packets_dropped;
  for (const auto& [name, value] : vimot::mip::named_counters(c)) process.set_counter(name, value);
}

int run(int argc, const char* const* argv) {
  vimot::Process process("vimot-imu-mip",
                         "LORD MicroStrain MIP IMU (3DM-GX4 family) on a serial port: sets the device up,\n"
                         "publishes IMU (imu_t) on the host clock, reopens on disconnect.\n"
                         "Configured by config/imu_mip.yaml (device.port, baud, rate, channels).",
                         /*config_required=*/true);
  if (!process.init(argc, argv)) return 0;

  const vimot::mip::ImuMipConfig config = vimot::mip::imu_mip_config_from(process.config());
  const std::string imu_channel = process.channel("imu", "IMU");
  vimot::mip::ImuMipDriver driver(
      config.driver, vimot::mip::stream_opener(config),
      [&](const vimot::ImuData& imu) { process.publish(imu_channel, vimot::to_lcm(imu)); },
      [&](const std::string& message, bool error) {
        if (error) {
          process.report_error(message);
        } else {
          vimot::log_info(message);
        }
      },
      vimot::wall_clock_utime);
  vimot::log_info("device ", config.port, " at ", config.baud, " baud, ", config.driver.rate_hz, " Hz, publishing ",
                  imu_channel);

  using Clock = std::chrono::steady_clock;
  auto next_heartbeat = Clock::now();
  while (!process.stop_requested()) {
    driver.step();
    if (Clock::now() >= next_heartbeat) {
      report_counters(process, driver.counters());
      process.publish_heartbeat();
      next_heartbeat += std::chrono::seconds(1);
    }
  }
  const vimot::mip::ImuMipCounters c = driver.counters();
  vimot::log_info("stopping: ", c.samples, " samples, ", c.bytes_dropped, " bytes and ", c.packets_dropped,
                  " packets dropped, ", c.reconnects, " reconnects");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

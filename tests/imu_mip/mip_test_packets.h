#pragma once
// Generated MIP traffic for the tests: IMU packets with known values, the
// way a 3DM-GX4 sends them (scaled accel, scaled gyro, GPS timestamp).

#include <cstdint>
#include <vector>

#include "drivers/imu_mip/mip_messages.h"

namespace vimot::mip::test {

/// A sensor data packet: accel (g), gyro (rad/s), GPS correlation time.
inline std::vector<uint8_t> imu_packet(const float accel_g[3], const float gyro[3], double time_of_week,
                                       uint16_t week) {
  FieldSpec a{kFieldScaledAccel, {}};
  FieldSpec w{kFieldScaledGyro, {}};
  for (int i = 0; i < 3; ++i) {
    append_f32(a.data, accel_g[i]);
    append_f32(w.data, gyro[i]);
  }
  FieldSpec t{kFieldGpsTimestamp, {}};
  append_f64(t.data, time_of_week);
  append_u16(t.data, week);
  append_u16(t.data, 0x0007);  // valid flags
  return encode_packet(kSensorDataSet, {a, w, t});
}

/// The k-th sample of a deterministic test sequence (values depend on k so a
/// lost or reordered packet is visible).
struct TestSample {
  float accel_g[3];
  float gyro[3];
  double time_of_week;
};

inline TestSample test_sample(int k, double rate_hz = 100.0) {
  TestSample s{};
  s.accel_g[0] = 0.01f * static_cast<float>(k % 7);
  s.accel_g[1] = -0.02f * static_cast<float>(k % 5);
  s.accel_g[2] = -1.0f;
  s.gyro[0] = 0.001f * static_cast<float>(k);
  s.gyro[1] = -0.5f;
  s.gyro[2] = 0.25f;
  s.time_of_week = 1000.0 + k / rate_hz;
  return s;
}

inline std::vector<uint8_t> test_packet(int k, double rate_hz = 100.0) {
  const TestSample s = test_sample(k, rate_hz);
  return imu_packet(s.accel_g, s.gyro, s.time_of_week, 2300);
}

/// An ACK (error 0) or NACK reply to `command` of `descriptor_set`, with
/// optional extra reply fields.
inline std::vector<uint8_t> ack_packet(uint8_t descriptor_set, uint8_t command, uint8_t error = 0,
                                       const std::vector<FieldSpec>& extra = {}) {
  std::vector<FieldSpec> fields = {{kFieldAckNack, {command, error}}};
  fields.insert(fields.end(), extra.begin(), extra.end());
  return encode_packet(descriptor_set, fields);
}

}  // namespace vimot::mip::test

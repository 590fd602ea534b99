#pragma once
// The MIP subset the IMU driver speaks: the sensor data set (0x80) decoded
// into SI units, and the commands of the start-up sequence with their
// ACK/NACK replies. Descriptors from the 3DM-GX4 data communications
// protocol manual (and mip_sdk for the newer shared timestamp fields).

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drivers/imu_mip/mip_protocol.h"

namespace vimot::mip {

// Descriptor sets.
constexpr uint8_t kBaseCommandSet = 0x01;
constexpr uint8_t k3dmCommandSet = 0x0C;
constexpr uint8_t kSensorDataSet = 0x80;

// Base command set.
constexpr uint8_t kCmdPing = 0x01;
constexpr uint8_t kCmdIdle = 0x02;
constexpr uint8_t kCmdResume = 0x06;
// 3DM command set.
constexpr uint8_t kCmdGetImuBaseRate = 0x06;
constexpr uint8_t kCmdImuMessageFormat = 0x08;
constexpr uint8_t kCmdEnableDataStream = 0x11;
constexpr uint8_t kReplyImuBaseRate = 0x83;
// Every command's reply carries this field: echoed command, error code.
constexpr uint8_t kFieldAckNack = 0xF1;

// Sensor data set fields.
constexpr uint8_t kFieldScaledAccel = 0x04;    // 3 x float, g
constexpr uint8_t kFieldScaledGyro = 0x05;     // 3 x float, rad/s
constexpr uint8_t kFieldGpsTimestamp = 0x12;   // double time of week s, u16 week, u16 flags (3DM-GX4)
constexpr uint8_t kFieldReferenceTime = 0xD5;  // u64 ns since power-up (shared field, newer devices)

/// Standard gravity: the MicroStrain scaled accelerometer's unit.
constexpr double kStandardGravity = 9.80665;
constexpr double kSecondsPerGpsWeek = 604800.0;

/// One IMU sample of the sensor data set, in SI units.
struct MipImuSample {
  Eigen::Vector3d a_IinI{Eigen::Vector3d::Zero()};  // m/s², specific force
  Eigen::Vector3d w_IinI{Eigen::Vector3d::Zero()};  // rad/s
  /// Device clock, seconds: the reference timestamp if present, else the
  /// GPS correlation timestamp (week * 604800 + time of week); none if the
  /// packet carries neither.
  std::optional<double> device_time;
};

enum class ImuDecode {
  kSample,     // a sample was decoded
  kNotImu,     // a valid packet without accelerometer and gyro (other set, magnetometer only, ...)
  kMalformed,  // an IMU field of the wrong size or a non-finite value
};

/// Decodes a sensor data packet; `why` says what was malformed.
ImuDecode decode_imu(const MipPacket& packet, MipImuSample& sample, std::string* why = nullptr);

/// The reply to one command, from its ACK/NACK field.
struct MipAck {
  uint8_t command{0};
  uint8_t error{0};  // 0 = ACK, else the device's NACK code
  bool ok() const { return error == 0; }
};

/// The ACK/NACK for `command` in a reply packet of `descriptor_set`, if any.
std::optional<MipAck> find_ack(const MipPacket& packet, uint8_t descriptor_set, uint8_t command);

/// Human-readable NACK code (3DM-GX4 manual).
std::string nack_name(uint8_t error);

// The start-up sequence's commands, as complete wire packets.
std::vector<uint8_t> command_idle();
std::vector<uint8_t> command_resume();
std::vector<uint8_t> command_get_imu_base_rate();
/// IMU message format (function 1 = use new settings): `descriptors` each at
/// base rate / decimation.
std::vector<uint8_t> command_imu_message_format(const std::vector<uint8_t>& descriptors, uint16_t decimation);
/// Enables (or disables) the IMU data stream (device selector 1).
std::vector<uint8_t> command_enable_imu_stream(bool enable);

/// The IMU base rate (Hz) in the reply to command_get_imu_base_rate().
std::optional<uint16_t> find_imu_base_rate(const MipPacket& reply);

}  // namespace vimot::mip

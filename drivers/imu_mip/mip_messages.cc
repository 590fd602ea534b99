#include "drivers/imu_mip/mip_messages.h"

#include <cmath>

namespace vimot::mip {

namespace {

bool read_vector3(const MipPacket& packet, const MipField& field, Eigen::Vector3d& out) {
  if (field.size != 12) return false;
  const uint8_t* p = packet.data(field);
  for (int i = 0; i < 3; ++i) out[i] = static_cast<double>(read_f32(p + 4 * i));
  return out.allFinite();
}

void set_why(std::string* why, const std::string& text) {
  if (why) *why = text;
}

// Function selector 1: apply the new settings.
constexpr uint8_t kFunctionApply = 0x01;
constexpr uint8_t kDeviceSelectorImu = 0x01;

}  // namespace

ImuDecode decode_imu(const MipPacket& packet, MipImuSample& sample, std::string* why) {
  if (packet.descriptor_set != kSensorDataSet) return ImuDecode::kNotImu;
  const MipField* accel = packet.find(kFieldScaledAccel);
  const MipField* gyro = packet.find(kFieldScaledGyro);
  if (!accel || !gyro) return ImuDecode::kNotImu;
  Eigen::Vector3d a_g;
  if (!read_vector3(packet, *accel, a_g)) {
    set_why(why, "scaled accelerometer field of " + std::to_string(accel->size) + " bytes (12 expected) or not finite");
    return ImuDecode::kMalformed;
  }
  if (!read_vector3(packet, *gyro, sample.w_IinI)) {
    set_why(why, "scaled gyro field of " + std::to_string(gyro->size) + " bytes (12 expected) or not finite");
    return ImuDecode::kMalformed;
  }
  sample.a_IinI = a_g * kStandardGravity;

  sample.device_time.reset();
  if (const MipField* ref = packet.find(kFieldReferenceTime)) {
    if (ref->size != 8) {
      set_why(why, "reference timestamp field of " + std::to_string(ref->size) + " bytes (8 expected)");
      return ImuDecode::kMalformed;
    }
    sample.device_time = static_cast<double>(read_u64(packet.data(*ref))) * 1e-9;
  } else if (const MipField* gps = packet.find(kFieldGpsTimestamp)) {
    const double tow = gps->size == 12 ? read_f64(packet.data(*gps)) : NAN;
    if (!std::isfinite(tow)) {
      set_why(why, "GPS timestamp field of " + std::to_string(gps->size) + " bytes (12 expected) or not finite");
      return ImuDecode::kMalformed;
    }
    sample.device_time = read_u16(packet.data(*gps) + 8) * kSecondsPerGpsWeek + tow;
  }
  return ImuDecode::kSample;
}

std::optional<MipAck> find_ack(const MipPacket& packet, uint8_t descriptor_set, uint8_t command) {
  if (packet.descriptor_set != descriptor_set) return std::nullopt;
  for (const MipField& f : packet.fields) {
    if (f.descriptor == kFieldAckNack && f.size == 2 && packet.data(f)[0] == command) {
      return MipAck{command, packet.data(f)[1]};
    }
  }
  return std::nullopt;
}

std::string nack_name(uint8_t error) {
  switch (error) {
    case 0x00: return "ACK";
    case 0x01: return "unknown command";
    case 0x02: return "invalid checksum";
    case 0x03: return "invalid parameter";
    case 0x04: return "command failed";
    case 0x05: return "command timeout";
    default: return "error code " + std::to_string(error);
  }
}

std::vector<uint8_t> command_idle() { return encode_packet(kBaseCommandSet, {{kCmdIdle, {}}}); }

std::vector<uint8_t> command_resume() { return encode_packet(kBaseCommandSet, {{kCmdResume, {}}}); }

std::vector<uint8_t> command_get_imu_base_rate() { return encode_packet(k3dmCommandSet, {{kCmdGetImuBaseRate, {}}}); }

std::vector<uint8_t> command_imu_message_format(const std::vector<uint8_t>& descriptors, uint16_t decimation) {
  std::vector<uint8_t> data = {kFunctionApply, static_cast<uint8_t>(descriptors.size())};
  for (uint8_t d : descriptors) {
    data.push_back(d);
    append_u16(data, decimation);
  }
  return encode_packet(k3dmCommandSet, {{kCmdImuMessageFormat, data}});
}

std::vector<uint8_t> command_enable_imu_stream(bool enable) {
  return encode_packet(k3dmCommandSet,
                       {{kCmdEnableDataStream, {kFunctionApply, kDeviceSelectorImu, static_cast<uint8_t>(enable)}}});
}

std::optional<uint16_t> find_imu_base_rate(const MipPacket& reply) {
  if (reply.descriptor_set != k3dmCommandSet) return std::nullopt;
  const MipField* f = reply.find(kReplyImuBaseRate);
  if (!f || f->size != 2) return std::nullopt;
  return read_u16(reply.data(*f));
}

}  // namespace vimot::mip

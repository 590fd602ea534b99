// Writes one libFuzzer seed per vimot type (the samples of the LCM type
// tests) in the input format of lcm_decode_fuzz.cc into DIR.
#include <fstream>
#include <iostream>
#include <string>

#include "common/process/lcm_type_registry.h"
#include "tests/lcmtypes/lcmtypes_samples.h"

namespace {
template <typename Msg>
void write_seed(const std::string& dir, const Msg& msg) {
  std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  const auto& types = vimot::vimot_lcm_types();
  for (std::size_t i = 0; i < types.size(); ++i) {
    if (types[i].fingerprint != Msg::getHash()) continue;
    std::ofstream out(dir + "/" + Msg::getTypeName(), std::ios::binary);
    out.put(static_cast<char>(i));
    out.write(reinterpret_cast<const char*>(buf.data() + 8), static_cast<std::streamsize>(buf.size() - 8));
  }
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 || std::string(argv[1]) == "--help") {
    std::cerr << "usage: fuzz_lcm_seeds DIR  (writes one seed per vimot LCM type into DIR)\n";
    return argc == 2 ? 0 : 2;
  }
  using namespace vimot_test;
  const std::string dir = argv[1];
  write_seed(dir, sample_features());
  write_seed(dir, sample_ground_truth());
  write_seed(dir, sample_heartbeat());
  write_seed(dir, sample_image());
  write_seed(dir, sample_imu());
  write_seed(dir, sample_mask());
  write_seed(dir, sample_metric_object_pose());
  write_seed(dir, sample_nav_state());
  write_seed(dir, sample_object_pose());
  write_seed(dir, sample_scale_estimate());
  write_seed(dir, sample_target_box());
  write_seed(dir, sample_target_prediction());
  write_seed(dir, sample_target_state());
  return 0;
}

// vimot-bench-mip-parser: throughput of the MIP parser + IMU decoder on the
// real recording ($VIMOT_DATA_DIR/mip/mip_data.bin, or --file), fed in
// serial-read-sized chunks, clean and with every 100th byte flipped (the
// resynchronisation path). CPU time of the calling thread; prints the machine.
#include <time.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/eval/machine.h"
#include "common/process/arg_parser.h"
#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"
#include "common/time/utime.h"

namespace {

using namespace vimot;

struct Result {
  double seconds{0.0};
  int64_t packets{0};
  int64_t samples{0};
  int64_t bytes_dropped{0};
};

Result run(const std::vector<uint8_t>& bytes, std::size_t chunk, int repeat) {
  Result r;
  mip::MipPacket packet;
  mip::MipImuSample sample;
  const double start = 1e-3 * thread_cpu_ms();
  for (int i = 0; i < repeat; ++i) {
    mip::MipParser parser;
    for (std::size_t pos = 0; pos < bytes.size(); pos += chunk) {
      parser.feed(bytes.data() + pos, std::min(chunk, bytes.size() - pos));
      while (parser.next(packet)) {
        if (mip::decode_imu(packet, sample) == mip::ImuDecode::kSample) ++r.samples;
      }
    }
    r.packets += parser.counters().packets;
    r.bytes_dropped += parser.counters().bytes_dropped;
  }
  r.seconds = 1e-3 * thread_cpu_ms() - start;
  return r;
}

void print(const char* label, const Result& r, std::size_t size, int repeat) {
  const double mb = static_cast<double>(size) * repeat / 1e6;
  std::printf("%-28s %8.1f MB/s  %7.0f ns/packet  %6lld packets  %6lld IMU samples  %7lld bytes dropped (per pass)\n",
              label, mb / r.seconds, 1e9 * r.seconds / static_cast<double>(r.packets),
              static_cast<long long>(r.packets / repeat), static_cast<long long>(r.samples / repeat),
              static_cast<long long>(r.bytes_dropped / repeat));
}

int run_main(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-mip-parser",
                 "MIP parser + IMU decoder throughput on the real recording, clean and corrupted.");
  args.add_option("file", "PATH", "MIP byte stream (default: $VIMOT_DATA_DIR/mip/mip_data.bin)");
  args.add_option("chunk", "BYTES", "bytes per feed() (a serial read)", "64");
  args.add_option("repeat", "N", "passes over the file", "50");
  if (!args.parse(argc, argv)) return 0;
  std::string path = args.given("file") ? args.get("file") : "";
  if (path.empty()) {
    const char* data = std::getenv("VIMOT_DATA_DIR");
    if (!data) throw ArgError("vimot-bench-mip-parser: give --file or set VIMOT_DATA_DIR");
    path = std::string(data) + "/mip/mip_data.bin";
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ArgError("vimot-bench-mip-parser: cannot open '" + path + "'");
  const std::vector<uint8_t> clean((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const int64_t chunk = args.get_int("chunk");
  const int64_t repeat = args.get_int("repeat");
  if (chunk < 1 || repeat < 1) throw ArgError("vimot-bench-mip-parser: --chunk and --repeat must be >= 1");
  std::vector<uint8_t> corrupt = clean;
  for (std::size_t i = 50; i < corrupt.size(); i += 100) corrupt[i] ^= 0x5A;

  const eval::MachineInfo machine = eval::machine_info();
  std::printf("%s: %zu bytes, chunks of %lld bytes, %lld passes, one thread (CPU time)\nmachine: %d CPUs, %s\n\n",
              path.c_str(), clean.size(), static_cast<long long>(chunk), static_cast<long long>(repeat),
              machine.nproc, machine.cpu_model.c_str());
  print("clean", run(clean, static_cast<std::size_t>(chunk), static_cast<int>(repeat)), clean.size(),
        static_cast<int>(repeat));
  print("every 100th byte flipped", run(corrupt, static_cast<std::size_t>(chunk), static_cast<int>(repeat)),
        corrupt.size(), static_cast<int>(repeat));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run_main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

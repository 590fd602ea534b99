// vimot-bench-lcm-decode: what the length check of decode_untrusted costs
// on top of the generated decoder, per message, for the message sizes the
// pipeline carries. Prints one row per message type.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "common/process/arg_parser.h"
#include "common/process/lcm_type_registry.h"
#include "common/process/process.h"
#include "tests/lcmtypes/lcmtypes_samples.h"

// GCC 12 flags the fingerprint read of the generated image_t decoder as
// maybe-uninitialized once it is inlined here (it is not: a short buffer
// returns before the compare).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace {

using Clock = std::chrono::steady_clock;

volatile int64_t g_sink = 0;  // keeps the compiler from dropping the work

// Best of 5 rounds of `reps` calls, in ns per call (the machine is shared).
template <typename Msg, typename F>
double ns_per_call(const std::vector<uint8_t>& buf, int reps, F&& f) {
  double best = 1e300;
  for (int round = 0; round < 5; ++round) {
    Msg msg;
    int64_t sum = 0;
    const auto t0 = Clock::now();
    for (int i = 0; i < reps; ++i) sum += f(buf, &msg);
    best = std::min(best, std::chrono::duration<double, std::nano>(Clock::now() - t0).count() / reps);
    g_sink = g_sink + sum;
  }
  return best;
}

template <typename Msg>
void row(const char* what, const Msg& sample, int reps) {
  std::vector<uint8_t> buf(static_cast<std::size_t>(sample.getEncodedSize()));
  sample.encode(buf.data(), 0, static_cast<int>(buf.size()));
  const int size = static_cast<int>(buf.size());
  const vimot::LcmStruct& layout = vimot::vimot_lcm_layout(Msg::getHash(), Msg::getTypeName());
  const auto raw = [size](const std::vector<uint8_t>& b, Msg* m) { return int64_t{m->decode(b.data(), 0, size)}; };
  const auto checked = [size](const std::vector<uint8_t>& b, Msg* m) {
    return int64_t{vimot::decode_untrusted(b.data(), size, m)};
  };
  const auto check_only = [size, &layout](const std::vector<uint8_t>& b, Msg*) {
    return int64_t{vimot::lcm_lengths_fit(layout, b.data(), size)};
  };
  ns_per_call<Msg>(buf, reps / 10 + 1, checked);  // warm-up
  const double t_raw = ns_per_call<Msg>(buf, reps, raw);
  const double t_checked = ns_per_call<Msg>(buf, reps, checked);
  const double t_check = ns_per_call<Msg>(buf, reps, check_only);
  std::printf("%-34s %9d %12.0f %12.0f %12.0f\n", what, size, t_raw, t_checked, t_check);
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] {
    vimot::ArgParser args("vimot-bench-lcm-decode",
                          "Times the generated LCM decoders with and without the length check\n"
                          "(decode_untrusted) on typical vimot messages.");
    args.add_option("reps", "N", "decodes per measurement", "20000");
    if (!args.parse(argc, argv)) return 0;
    const int reps = std::stoi(args.get("reps"));
    std::printf("%-34s %9s %12s %12s %12s\n", "message", "bytes", "decode ns", "checked ns", "check ns");
    row("imu_t", vimot_test::sample_imu(), reps);
    row("nav_state_t", vimot_test::sample_nav_state(), reps);
    row("features_t, 300 observations", vimot_test::sample_features(300), reps);
    vimot::image_t image = vimot_test::sample_image();
    image.width = 752;
    image.height = 480;
    image.row_stride = 752;
    image.pixelformat = vimot::image_t::PIXEL_FORMAT_GRAY;
    image.size = image.row_stride * image.height;
    image.data.assign(static_cast<std::size_t>(image.size), 128);
    row("image_t, 752x480 gray, 2 metadata", image, reps / 20 + 1);
    return 0;
  });
}

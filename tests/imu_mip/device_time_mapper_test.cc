// The device -> host time filter on generated clocks with a known truth:
// host time of sample k is h_k = offset0 + d_k (1 + skew), it arrives at
// h_k + L_min + jitter (+ occasional long stalls). The filter must give
// h_k + L_min (L_min is unobservable) to within a fraction of the jitter,
// never go backwards, never be later than the arrival, and re-lock after a
// device restart or a host clock step.
#include <catch2/catch.hpp>

#include <random>

#include "drivers/imu_mip/device_time_mapper.h"

using vimot::DeviceTimeMapper;

namespace {

constexpr double kRate = 200.0;        // Hz
constexpr double kMinLatency = 500.0;  // µs
constexpr double kJitterMean = 1000.0; // µs, exponential

struct Stream {
  std::mt19937 rng{42};
  std::exponential_distribution<double> jitter{1.0 / kJitterMean};
  std::uniform_real_distribution<double> unit{0.0, 1.0};

  // Arrival time for a true host time: 2 % of samples stall 5-40 ms.
  double arrival(double host_us) {
    double latency = kMinLatency + jitter(rng);
    if (unit(rng) < 0.02) latency += 5000.0 + 35000.0 * unit(rng);
    return host_us + latency;
  }
};

struct Errors {
  double min{1e18}, max{-1e18}, arrival_max{-1e18};
};

// Runs n samples from device time d0; host = offset0 + d (1 + skew).
// Errors are of mapped - (host + L_min), counted after `settle` samples.
// `held`: the host clock stepped back, so the output (which may not go back)
// is allowed to be later than the arrivals until the truth catches up.
Errors run(DeviceTimeMapper& mapper, Stream& stream, double d0, int n, double offset0_us, double skew, int settle,
           int64_t& last_out, bool held = false) {
  Errors e;
  for (int k = 0; k < n; ++k) {
    const double d = d0 + k / kRate;
    const double host = offset0_us + d * 1e6 * (1.0 + skew);
    const int64_t arrival = static_cast<int64_t>(stream.arrival(host));
    const int64_t out = mapper.map(d, arrival);
    REQUIRE(out > last_out);     // never backwards, never repeated
    if (!held) REQUIRE(out <= arrival + 1);  // never later than the arrival (+ rounding)
    last_out = out;
    if (k >= settle) {
      const double err = static_cast<double>(out) - (host + kMinLatency);
      e.min = std::min(e.min, err);
      e.max = std::max(e.max, err);
      e.arrival_max = std::max(e.arrival_max, static_cast<double>(arrival) - (host + kMinLatency));
    }
  }
  return e;
}

}  // namespace

TEST_CASE("Jittered arrivals: mapped time within a fraction of the jitter of the truth, for +-50 ppm skew") {
  for (const double skew : {50e-6, -50e-6, 0.0}) {
    CAPTURE(skew);
    DeviceTimeMapper mapper;
    Stream stream;
    int64_t last = std::numeric_limits<int64_t>::min();
    // 60 s at 200 Hz; settle for 1 s.
    const Errors e = run(mapper, stream, 1234.5, 12000, 1.7e15, skew, 200, last);
    // Lower bound: the envelope never drops below the true minimum latency
    // (+-1 µs rounding). Upper: a quick sample (jitter < 0.1 ms: ~10 % of
    // them) comes every few samples, so the error stays well under the
    // 1 ms mean jitter, and far under the 40 ms stalls the arrival stamps carry.
    CHECK(e.min >= -1.0);
    CHECK(e.max < 0.4 * kJitterMean);
    CHECK(e.arrival_max > 5000.0);
  }
}

TEST_CASE("A device clock restart re-locks; output keeps going forward") {
  DeviceTimeMapper mapper;
  Stream stream;
  int64_t last = std::numeric_limits<int64_t>::min();
  run(mapper, stream, 500.0, 2000, 1.7e15, 20e-6, 0, last);
  // The device restarts at 0 while the host goes on (host offset moved so
  // host time continues 1 s after the previous sample).
  const double host_now = 1.7e15 + (500.0 + 2000 / kRate) * 1e6 * (1.0 + 20e-6);
  const Errors e = run(mapper, stream, 0.0, 2000, host_now + 1e6, 20e-6, 200, last);
  CHECK(mapper.relocks() == 1);
  CHECK(e.min >= -1.0);
  CHECK(e.max < 0.4 * kJitterMean);
}

TEST_CASE("A host clock step forward re-locks after relock_after; a backward step holds the output") {
  vimot::DeviceTimeMapperOptions options;
  options.relock_after = 1.0;
  DeviceTimeMapper mapper(options);
  Stream stream;
  int64_t last = std::numeric_limits<int64_t>::min();
  run(mapper, stream, 100.0, 2000, 1.7e15, 0.0, 0, last);
  // Host clock jumps +3 s (e.g. NTP step): after 1 s of device time the
  // filter follows; check from 1.5 s on.
  const Errors fwd = run(mapper, stream, 110.0, 2000, 1.7e15 + 3e6, 0.0, 300, last);
  CHECK(mapper.relocks() == 1);
  CHECK(fwd.min >= -1.0);
  CHECK(fwd.max < 0.4 * kJitterMean);
  // Host clock steps back 0.5 s: output may not go back (run() checks it), so
  // it advances by 1 µs until the truth catches up, then tracks again.
  const Errors back = run(mapper, stream, 120.0, 2000, 1.7e15 + 3e6 - 0.5e6, 0.0, 200, last, /*held=*/true);
  CHECK(back.max < 0.4 * kJitterMean);
  CHECK(back.min >= -1.0);
}

TEST_CASE("Bad options and a non-finite device time are refused") {
  vimot::DeviceTimeMapperOptions bad;
  bad.max_drift = -1.0;
  CHECK_THROWS_WITH(DeviceTimeMapper(bad), Catch::Contains("max_drift"));
  DeviceTimeMapper mapper;
  CHECK_THROWS_AS(mapper.map(std::nan(""), 0), std::invalid_argument);
}

// Determinism and timing: the same config gives the same events bit for bit,
// a different seed changes the noise but not the truth, a different map seed
// the map; utimes come from integer ticks and are ordered.
#include <catch2/catch.hpp>

#include <cstring>
#include <type_traits>

#include "common/sim/simulator.h"
#include "tests/sim/sim_test_util.h"

using namespace vimot;
using namespace vimot::sim;

namespace {

template <typename M>
bool same_bits(const M& a, const M& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

bool same_event(const SimEvent& a, const SimEvent& b) {
  if (a.index() != b.index()) return false;
  if (const auto* x = std::get_if<ImuSample>(&a)) {
    const auto& y = std::get<ImuSample>(b);
    return x->utime == y.utime && same_bits(x->w_IinI, y.w_IinI) && same_bits(x->a_IinI, y.a_IinI);
  }
  if (const auto* x = std::get_if<GroundTruth>(&a)) {
    const auto& y = std::get<GroundTruth>(b);
    return x->utime == y.utime && same_bits(x->q_GtoI, y.q_GtoI) && same_bits(x->p_IinG, y.p_IinG) &&
           same_bits(x->v_IinG, y.v_IinG) && same_bits(x->w_IinI, y.w_IinI) && same_bits(x->a_IinG, y.a_IinG) &&
           same_bits(x->bias_gyro, y.bias_gyro) && same_bits(x->bias_accel, y.bias_accel) &&
           x->has_target == y.has_target && same_bits(x->q_GtoT, y.q_GtoT) && same_bits(x->p_TinG, y.p_TinG) &&
           same_bits(x->v_TinT, y.v_TinT) && same_bits(x->w_TinT, y.w_TinT);
  }
  const auto& x = std::get<CameraFrame>(a);
  const auto& y = std::get<CameraFrame>(b);
  if (x.utime != y.utime || x.observations.size() != y.observations.size()) return false;
  for (std::size_t k = 0; k < x.observations.size(); ++k) {
    const FeatureObservation& o = x.observations[k];
    const FeatureObservation& p = y.observations[k];
    if (o.feature_id != p.feature_id || o.camera_id != p.camera_id || o.is_target != p.is_target ||
        !same_bits(o.pixel, p.pixel) || !same_bits(o.normalized, p.normalized)) {
      return false;
    }
  }
  return true;
}

std::vector<SimEvent> events_of(const SimConfig& c) {
  Simulator sim(c);
  std::vector<SimEvent> out;
  while (auto e = sim.next()) out.push_back(std::move(*e));
  return out;
}

SimConfig short_paper(uint64_t seed, uint64_t map_seed) {
  SimConfig c = test::paper_config();
  c.duration = 4.0;
  c.seed = seed;
  c.map_seed = map_seed;
  return c;
}

}  // namespace

TEST_CASE("The same seeds give the identical event sequence, bit for bit") {
  const std::vector<SimEvent> a = events_of(short_paper(7, 3));
  const std::vector<SimEvent> b = events_of(short_paper(7, 3));
  REQUIRE(a.size() == b.size());
  REQUIRE(a.size() == 801 + 801 + 41);
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size(); ++k) differing += !same_event(a[k], b[k]);
  CHECK(differing == 0);
}

TEST_CASE("A shorter run is an exact prefix of the longer one") {
  SimConfig longer = short_paper(7, 3);
  longer.duration = 6.0;
  const std::vector<SimEvent> a = events_of(short_paper(7, 3)), b = events_of(longer);
  REQUIRE(b.size() > a.size());
  std::size_t differing = 0;
  for (std::size_t k = 0; k < a.size(); ++k) differing += !same_event(a[k], b[k]);
  CHECK(differing == 0);
}

TEST_CASE("A different seed changes the measurement noise but neither the truth nor the map") {
  const SimConfig c1 = short_paper(7, 3), c2 = short_paper(8, 3);
  const std::vector<SimEvent> a = events_of(c1), b = events_of(c2);
  REQUIRE(a.size() == b.size());
  std::size_t imu_diff = 0, imu_n = 0, gt_pose_diff = 0, frames_diff = 0;
  for (std::size_t k = 0; k < a.size(); ++k) {
    if (const auto* x = std::get_if<ImuSample>(&a[k])) {
      ++imu_n;
      imu_diff += !same_event(a[k], b[k]);
      CHECK(x->utime == std::get<ImuSample>(b[k]).utime);
    } else if (const auto* g = std::get_if<GroundTruth>(&a[k])) {
      const auto& h = std::get<GroundTruth>(b[k]);
      gt_pose_diff += !(same_bits(g->p_IinG, h.p_IinG) && same_bits(g->q_GtoI, h.q_GtoI) &&
                        same_bits(g->p_TinG, h.p_TinG));
    } else {
      frames_diff += !same_event(a[k], b[k]);
    }
  }
  CHECK(imu_diff == imu_n);  // every IMU sample has different noise
  CHECK(gt_pose_diff == 0);  // the trajectory is the same
  CHECK(frames_diff == 41);  // every frame has different pixel noise
  Simulator s1(c1), s2(c2);
  REQUIRE(s1.landmarks().size() == s2.landmarks().size());
  for (std::size_t k = 0; k < s1.landmarks().size(); ++k) {
    CHECK(same_bits(s1.landmarks()[k].p, s2.landmarks()[k].p));
  }
  // A different map seed gives a different map.
  Simulator s3(short_paper(7, 4));
  REQUIRE(s3.landmarks().size() == s1.landmarks().size());
  std::size_t moved = 0;
  for (std::size_t k = 0; k < s1.landmarks().size(); ++k) moved += !same_bits(s1.landmarks()[k].p, s3.landmarks()[k].p);
  CHECK(moved == s1.landmarks().size());
}

TEST_CASE("Utimes come from integer ticks: camera frames fall on IMU samples and events are ordered") {
  SimConfig c = short_paper(1, 1);
  c.start_utime = 1'600'000'000'000'000;
  for (const double imu_rate : {200.0, 400.0}) {
    c.imu.rate_hz = imu_rate;
    Simulator sim(c);
    const int64_t period = static_cast<int64_t>(1e6 / imu_rate);
    int64_t last = 0, n_imu = 0, n_cam = 0;
    int last_kind = -1;
    sim.run([&](const SimEvent& e) {
      const int64_t u = std::visit([](const auto& x) { return x.utime; }, e);
      CHECK(u >= last);
      if (u == last) CHECK(static_cast<int>(e.index()) > last_kind);  // IMU, truth, then frame
      if (std::holds_alternative<ImuSample>(e)) {
        CHECK(u == c.start_utime + n_imu * period);
        ++n_imu;
      }
      if (std::holds_alternative<CameraFrame>(e)) {
        CHECK(u == c.start_utime + n_cam * 100000);  // 10 Hz
        CHECK((u - c.start_utime) % period == 0);    // on an IMU sample
        ++n_cam;
      }
      last = u;
      last_kind = static_cast<int>(e.index());
    });
    CHECK(n_imu == static_cast<int64_t>(4.0 * imu_rate) + 1);
    CHECK(n_cam == 41);
    CHECK(sim.end_utime() == c.start_utime + 4'000'000);
  }
  // Rates that do not divide 1e6 µs: rounded per tick, no accumulated drift.
  c.imu.rate_hz = 300.0;
  c.camera.rate_hz = 7.0;
  Simulator sim(c);
  CHECK(sim.imu_utime(3) == c.start_utime + 10000);
  CHECK(sim.imu_utime(1) == c.start_utime + 3333);
  CHECK(sim.imu_utime(2) == c.start_utime + 6667);
  CHECK(sim.camera_utime(7) == c.start_utime + 1'000'000);
  CHECK(sim.imu_sample_count() == 1201);
  CHECK(sim.camera_frame_count() == 29);  // k / 7 <= 4 s
}

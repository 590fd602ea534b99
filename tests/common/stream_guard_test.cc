// StreamGuard: one bad timestamp is rejected without moving the clock, a
// clock that really moved is a source reset after `reset_after` consistent
// messages, and gaps against the expected period count lost messages.
#include <catch2/catch.hpp>

#include "common/process/stream_guard.h"

using vimot::StreamGuard;
using vimot::StreamGuardOptions;
using vimot::StreamVerdict;

namespace {
StreamGuardOptions options() {
  StreamGuardOptions o;
  o.expected_period_s = 0.005;  // 200 Hz
  o.max_forward_jump_s = 0.5;
  o.max_backward_jump_s = 0.5;
  o.reset_after = 3;
  return o;
}
}  // namespace

TEST_CASE("a single future or past timestamp is rejected, the clock stays") {
  StreamGuard g("IMU", options());
  CHECK(g.check(1'000'000).verdict == StreamVerdict::kAccept);
  CHECK(g.check(1'005'000).verdict == StreamVerdict::kAccept);
  CHECK(g.check(1'001'005'000).verdict == StreamVerdict::kRejectJump);  // +1000 s
  CHECK(g.check(1'010'000).verdict == StreamVerdict::kAccept);
  CHECK(g.check(10'000).verdict == StreamVerdict::kRejectJump);  // -1 s
  const auto c = g.check(1'015'000);
  CHECK(c.verdict == StreamVerdict::kAccept);
  CHECK(c.lost == 0);
  CHECK(g.rejected() == 2);
  CHECK(g.source_resets() == 0);
  // Slightly old or duplicate: the consumer's to drop, the clock unchanged.
  CHECK(g.check(1'012'000).verdict == StreamVerdict::kAccept);
  CHECK(g.check(1'020'000).lost == 0);
}

TEST_CASE("a clock that moved and stays there is a source reset") {
  StreamGuard g("IMU", options());
  g.check(10'000'000);
  CHECK(g.check(5'000'000).verdict == StreamVerdict::kRejectJump);
  CHECK(g.check(5'005'000).verdict == StreamVerdict::kRejectJump);
  CHECK(g.check(5'010'000).verdict == StreamVerdict::kSourceReset);
  CHECK(g.check(5'015'000).verdict == StreamVerdict::kAccept);
  CHECK(g.source_resets() == 1);
  // Inconsistent suspects (scattered garbage) never make a reset.
  for (int i = 0; i < 10; ++i) {
    CHECK(g.check(i % 2 ? 900'000'000 : 100'000'000 + i).verdict == StreamVerdict::kRejectJump);
  }
  CHECK(g.source_resets() == 1);
}

TEST_CASE("gaps count the messages lost against the expected period") {
  StreamGuard g("IMU", options());
  g.check(0);
  CHECK(g.check(5'000).lost == 0);
  CHECK(g.check(20'000).lost == 2);   // 10 and 15 ms missing
  CHECK(g.check(26'000).lost == 0);   // jitter is not loss
  CHECK(g.check(126'000).lost == 19);
  CHECK(g.lost() == 21);
  StreamGuardOptions unknown = options();
  unknown.expected_period_s = 0.0;
  StreamGuard u("FEATURES", unknown);
  u.check(0);
  CHECK(u.check(400'000).lost == 0);
}

TEST_CASE("a rejected message fills its slot: each missing sample counted once") {
  StreamGuard g("IMU", options());
  g.check(0);
  CHECK(g.check(5'000).lost == 0);
  // The sample of 10 ms arrives with a bad stamp: rejected, not lost too.
  CHECK(g.check(1'000'010'000).verdict == StreamVerdict::kRejectJump);
  CHECK(g.check(15'000).lost == 0);
  // 20 and 25 ms never arrive, 30 ms comes stamped in the past: 2 lost, 1 rejected.
  CHECK(g.check(-1'000'000).verdict == StreamVerdict::kRejectJump);
  CHECK(g.check(35'000).lost == 2);
  CHECK(g.lost() == 2);
  CHECK(g.rejected() == 2);
  // A rejected message where no slot was missing does not hide a later gap.
  CHECK(g.check(900'000'000).verdict == StreamVerdict::kRejectJump);
  CHECK(g.check(40'000).lost == 0);
  CHECK(g.check(50'000).lost == 1);
}

TEST_CASE("an outage longer than a jump is a source reset that counts what it skipped") {
  StreamGuard g("IMU", options());
  g.check(0);
  // 0.7 s of messages never arrived (a queue overflowed): 139 missing, then
  // 2 rejected as suspects before the third makes the reset.
  CHECK(g.check(700'000).verdict == StreamVerdict::kRejectJump);
  CHECK(g.check(705'000).verdict == StreamVerdict::kRejectJump);
  const auto c = g.check(710'000);
  CHECK(c.verdict == StreamVerdict::kSourceReset);
  CHECK(c.lost == 139);
  CHECK(g.check(715'000).lost == 0);
  // Another stream's source reset restarts this clock: a forward step from
  // the old one is still counted, a step back (a clock moved back) is not.
  g.reset();
  CHECK(g.check(815'000).lost == 19);
  g.reset();
  CHECK(g.check(100'000).lost == 0);
  CHECK(g.check(105'000).lost == 0);
  // A clock moved far ahead (beyond max_outage_s) is no outage.
  for (int64_t t : {900'000'000, 900'005'000}) CHECK(g.check(t).verdict == StreamVerdict::kRejectJump);
  const auto far = g.check(900'010'000);
  CHECK(far.verdict == StreamVerdict::kSourceReset);
  CHECK(far.lost == 0);
  CHECK(g.lost() == 139 + 19);
}

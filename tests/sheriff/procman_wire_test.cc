// The bot_procman types built here are libbot2 procman's on the wire: their
// fingerprints equal the ones lcm_fingerprint() computes from layouts
// written from libbot2's bot2-procman/lcmtypes/*.lcm (independently of the
// .lcm files lcm-gen read), a message laid out byte by byte per the LCM
// encoding decodes through the generated code, and lengths that do not fit
// are rejected before anything is allocated.
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "procs/sheriff/procman_lcm.h"

namespace {

void PutBigEndian(std::vector<uint8_t>* out, uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out->push_back(static_cast<uint8_t>(v >> (8 * i)));
}

void PutString(std::vector<uint8_t>* out, const std::string& s) {
  PutBigEndian(out, s.size() + 1, 4);  // length counts the terminating NUL
  out->insert(out->end(), s.begin(), s.end());
  out->push_back(0);
}

}  // namespace

TEST_CASE("bot_procman fingerprints are libbot2's") {
  // The layouts are written from libbot2's definitions; lcm-gen hashed our
  // .lcm files. Equal fingerprints: the same members, types and order.
  const vimot::sheriff::ProcmanLayouts& l = vimot::sheriff::procman_layouts();
  CHECK(bot_procman::command2_t::getHash() == vimot::lcm_fingerprint(l.command2));
  CHECK(bot_procman::sheriff_cmd2_t::getHash() == vimot::lcm_fingerprint(l.sheriff_cmd2));
  CHECK(bot_procman::deputy_cmd2_t::getHash() == vimot::lcm_fingerprint(l.deputy_cmd2));
  CHECK(bot_procman::orders2_t::getHash() == vimot::lcm_fingerprint(l.orders2));
  CHECK(bot_procman::info2_t::getHash() == vimot::lcm_fingerprint(l.info2));
  CHECK(bot_procman::printf_t::getHash() == vimot::lcm_fingerprint(l.printf_msg));
  CHECK(bot_procman::discovery_t::getHash() == vimot::lcm_fingerprint(l.discovery));
  // A renamed member changes it (the check can fail).
  const vimot::LcmStruct renamed{"printf_t", {{"utime", vimot::LcmKind::kInt64},
                                              {"deputy_name", vimot::LcmKind::kString},
                                              {"sheriff_id", vimot::LcmKind::kInt32},
                                              {"txt", vimot::LcmKind::kString}}};
  CHECK(bot_procman::printf_t::getHash() != vimot::lcm_fingerprint(renamed));
}

TEST_CASE("orders claiming more commands than their bytes hold are rejected before decoding") {
  std::vector<uint8_t> bytes;
  PutBigEndian(&bytes, static_cast<uint64_t>(bot_procman::orders2_t::getHash()), 8);
  PutBigEndian(&bytes, 1, 8);
  PutString(&bytes, "vehicle");
  PutString(&bytes, "s");
  PutBigEndian(&bytes, 100'000'000, 4);  // ncmds, with no commands following
  bot_procman::orders2_t msg;
  CHECK_FALSE(vimot::sheriff::DecodeProcman(bytes.data(), static_cast<int>(bytes.size()), &msg));
  CHECK(msg.cmds.empty());
  // Cut short, and with a byte too many.
  vimot::sheriff::DeputyOrders orders;
  orders.host = "vehicle";
  orders.cmds.resize(1);
  const bot_procman::orders2_t good = vimot::sheriff::ToLcm(orders);
  std::vector<uint8_t> buf(static_cast<std::size_t>(good.getEncodedSize()));
  good.encode(buf.data(), 0, static_cast<int>(buf.size()));
  CHECK(vimot::sheriff::DecodeProcman(buf.data(), static_cast<int>(buf.size()), &msg));
  CHECK_FALSE(vimot::sheriff::DecodeProcman(buf.data(), static_cast<int>(buf.size()) - 1, &msg));
  buf.push_back(0);
  CHECK_FALSE(vimot::sheriff::DecodeProcman(buf.data(), static_cast<int>(buf.size()), &msg));
}

TEST_CASE("a printf_t laid out per the LCM encoding decodes through our types") {
  std::vector<uint8_t> bytes;
  // libbot2's printf_t fingerprint, from its definition.
  PutBigEndian(&bytes,
               static_cast<uint64_t>(vimot::lcm_fingerprint(vimot::sheriff::procman_layouts().printf_msg)),
               8);
  PutBigEndian(&bytes, 1'700'000'000'000'000ULL, 8);
  PutString(&bytes, "vehicle");
  PutBigEndian(&bytes, 7, 4);
  PutString(&bytes, "hello\n");

  bot_procman::printf_t msg;
  REQUIRE(msg.decode(bytes.data(), 0, static_cast<int>(bytes.size())) ==
          static_cast<int>(bytes.size()));
  const vimot::sheriff::DeputyOutput out = vimot::sheriff::FromLcm(msg);
  CHECK(out.utime == 1'700'000'000'000'000LL);
  CHECK(out.deputy_name == "vehicle");
  CHECK(out.sheriff_id == 7);
  CHECK(out.text == "hello\n");

  // And our encoder writes exactly these bytes.
  const bot_procman::printf_t back = vimot::sheriff::ToLcm(out);
  std::vector<uint8_t> encoded(static_cast<std::size_t>(back.getEncodedSize()));
  REQUIRE(back.encode(encoded.data(), 0, static_cast<int>(encoded.size())) ==
          static_cast<int>(encoded.size()));
  CHECK(encoded == bytes);
}

TEST_CASE("orders survive the wire: sheriff side to deputy side") {
  vimot::sheriff::DeputyOrders orders;
  orders.utime = 123;
  orders.host = "vehicle";
  orders.sheriff_name = "s";
  vimot::sheriff::CommandOrder c;
  c.cmd.exec = "sleep 1";
  c.cmd.name = "sleeper";
  c.cmd.group = "0.sensors/imu";
  c.cmd.auto_respawn = true;
  c.cmd.stop_signal = 15;
  c.cmd.stop_time_allowed_s = 2.5;
  c.desired_runid = 4;
  c.force_quit = true;
  c.sheriff_id = 9;
  orders.cmds.push_back(c);
  const bot_procman::orders2_t msg = vimot::sheriff::ToLcm(orders);
  std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
  msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  bot_procman::orders2_t decoded;
  REQUIRE(decoded.decode(buf.data(), 0, static_cast<int>(buf.size())) ==
          static_cast<int>(buf.size()));
  const vimot::sheriff::DeputyOrders back = vimot::sheriff::FromLcm(decoded);
  REQUIRE(back.cmds.size() == 1);
  CHECK(back.cmds[0].cmd == c.cmd);
  CHECK(back.cmds[0].desired_runid == 4);
  CHECK(back.cmds[0].force_quit);
  CHECK(back.cmds[0].sheriff_id == 9);
  CHECK(back.host == "vehicle");
  CHECK(back.sheriff_name == "s");
}

// The bot_procman types built here are libbot2 procman's on the wire: their
// fingerprints equal the ones computed, independently of lcm-gen, from the
// member lists of libbot2's bot2-procman/lcmtypes/*.lcm (LCM's type hash:
// member names, primitive type names, array dimensions; nested types folded
// in and rotated), and a message laid out byte by byte per the LCM encoding
// decodes through the generated code.
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "procs/sheriff/procman_lcm.h"

namespace {

struct Member {
  std::string name;
  /// Empty for a nested struct type (its name is not hashed).
  std::string primitive;
  /// Variable-length dimension: the name of its length member.
  std::string var_dim;
};

// LCM's hash step: rotate-ish shift by one byte, then add.
int64_t Update(int64_t v, int c) {
  const uint64_t u = static_cast<uint64_t>(v);
  const uint64_t shifted = (u << 8) ^ static_cast<uint64_t>(v >> 55);
  return static_cast<int64_t>(shifted + static_cast<uint64_t>(c));
}

int64_t Update(int64_t v, const std::string& s) {
  v = Update(v, static_cast<int>(s.size()));
  for (const char c : s) v = Update(v, c);
  return v;
}

int64_t BaseHash(const std::vector<Member>& members) {
  int64_t v = 0x12345678;
  for (const Member& m : members) {
    v = Update(v, m.name);
    if (!m.primitive.empty()) v = Update(v, m.primitive);
    v = Update(v, m.var_dim.empty() ? 0 : 1);
    if (!m.var_dim.empty()) {
      v = Update(v, 1);  // dimension mode: variable
      v = Update(v, m.var_dim);
    }
  }
  return v;
}

// Fingerprint of a type: its base hash plus its nested types', rotated left
// by one bit.
int64_t Fingerprint(int64_t base, const std::vector<int64_t>& nested = {}) {
  uint64_t h = static_cast<uint64_t>(base);
  for (const int64_t n : nested) h += static_cast<uint64_t>(n);
  return static_cast<int64_t>((h << 1) + ((h >> 63) & 1));
}

// Member lists as libbot2 defines them.
const std::vector<Member> kCommand2 = {
    {"exec_str", "string", ""},          {"command_name", "string", ""},
    {"group", "string", ""},             {"auto_respawn", "boolean", ""},
    {"stop_signal", "int8_t", ""},       {"stop_time_allowed", "float", ""},
    {"num_options", "int32_t", ""},      {"option_names", "string", "num_options"},
    {"option_values", "string", "num_options"}};
const std::vector<Member> kSheriffCmd2 = {{"cmd", "", ""},
                                          {"desired_runid", "int32_t", ""},
                                          {"force_quit", "int8_t", ""},
                                          {"sheriff_id", "int32_t", ""}};
const std::vector<Member> kDeputyCmd2 = {
    {"cmd", "", ""},          {"pid", "int32_t", ""},           {"actual_runid", "int32_t", ""},
    {"exit_code", "int32_t", ""}, {"cpu_usage", "float", ""},  {"mem_vsize_bytes", "int64_t", ""},
    {"mem_rss_bytes", "int64_t", ""}, {"sheriff_id", "int32_t", ""}};
const std::vector<Member> kOrders2 = {
    {"utime", "int64_t", ""},   {"host", "string", ""},
    {"sheriff_name", "string", ""}, {"ncmds", "int32_t", ""},
    {"cmds", "", "ncmds"},      {"num_options", "int32_t", ""},
    {"option_names", "string", "num_options"}, {"option_values", "string", "num_options"}};
const std::vector<Member> kInfo2 = {
    {"utime", "int64_t", ""},  {"host", "string", ""},  {"cpu_load", "float", ""},
    {"phys_mem_total_bytes", "int64_t", ""}, {"phys_mem_free_bytes", "int64_t", ""},
    {"swap_total_bytes", "int64_t", ""},     {"swap_free_bytes", "int64_t", ""},
    {"ncmds", "int32_t", ""},  {"cmds", "", "ncmds"}, {"num_options", "int32_t", ""},
    {"option_names", "string", "num_options"}, {"option_values", "string", "num_options"}};
const std::vector<Member> kPrintf = {{"utime", "int64_t", ""},
                                     {"deputy_name", "string", ""},
                                     {"sheriff_id", "int32_t", ""},
                                     {"text", "string", ""}};
const std::vector<Member> kDiscovery = {
    {"utime", "int64_t", ""}, {"host", "string", ""}, {"nonce", "int64_t", ""}};

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
  const int64_t command2 = Fingerprint(BaseHash(kCommand2));
  CHECK(bot_procman::command2_t::getHash() == command2);
  CHECK(bot_procman::sheriff_cmd2_t::getHash() == Fingerprint(BaseHash(kSheriffCmd2), {command2}));
  CHECK(bot_procman::deputy_cmd2_t::getHash() == Fingerprint(BaseHash(kDeputyCmd2), {command2}));
  // orders2_t nests sheriff_cmd2_t, which nests command2_t: the inner hash
  // is folded in at each level.
  const int64_t sheriff_inner = Fingerprint(BaseHash(kSheriffCmd2), {command2});
  const int64_t deputy_inner = Fingerprint(BaseHash(kDeputyCmd2), {command2});
  CHECK(bot_procman::orders2_t::getHash() == Fingerprint(BaseHash(kOrders2), {sheriff_inner}));
  CHECK(bot_procman::info2_t::getHash() == Fingerprint(BaseHash(kInfo2), {deputy_inner}));
  CHECK(bot_procman::printf_t::getHash() == Fingerprint(BaseHash(kPrintf)));
  CHECK(bot_procman::discovery_t::getHash() == Fingerprint(BaseHash(kDiscovery)));
  // A changed member would change it (the check can fail).
  std::vector<Member> renamed = kPrintf;
  renamed[3].name = "txt";
  CHECK(bot_procman::printf_t::getHash() != Fingerprint(BaseHash(renamed)));
}

TEST_CASE("a printf_t laid out per the LCM encoding decodes through our types") {
  std::vector<uint8_t> bytes;
  PutBigEndian(&bytes, static_cast<uint64_t>(Fingerprint(BaseHash(kPrintf))), 8);
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

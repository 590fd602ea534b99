// The length check every decoder of outside bytes runs first
// (decode_untrusted): valid messages of every vimot type pass, and no
// corrupted length in any of them makes a decoder allocate more than a small
// multiple of the message's own size. Allocations are counted by replacing
// the global operator new in this test binary.
#include <catch2/catch.hpp>

#include <atomic>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <set>

#include "common/process/lcm_type_registry.h"
#include "common/process/process.h"
#include "../lcmtypes/lcmtypes_samples.h"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::size_t> g_allocated{0};
}  // namespace

// GCC 12 flags free() in a replaced operator delete as mismatched with new.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

void* operator new(std::size_t n) {
  if (g_counting) g_allocated += n;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace {

using vimot::decode_untrusted;
using vimot::lcm_lengths_fit;

struct Sample {
  std::string type;
  std::vector<uint8_t> bytes;
  bool (*decodes)(const void*, int);  // decode_untrusted as the registered type
};

template <typename Msg>
Sample sample(const Msg& msg) {
  std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
  REQUIRE(msg.encode(buf.data(), 0, static_cast<int>(buf.size())) == static_cast<int>(buf.size()));
  return Sample{Msg::getTypeName(), buf, +[](const void* data, int size) {
                  Msg out;
                  return decode_untrusted(data, size, &out);
                }};
}

std::vector<Sample> all_samples() {
  using namespace vimot_test;
  return {sample(sample_features()),       sample(sample_ground_truth()),     sample(sample_heartbeat()),
          sample(sample_image()),          sample(sample_imu()),              sample(sample_mask()),
          sample(sample_metric_object_pose()), sample(sample_nav_state()),    sample(sample_object_pose()),
          sample(sample_scale_estimate()), sample(sample_target_box()),       sample(sample_target_prediction()),
          sample(sample_target_state())};
}

// Bytes operator new handed out while running f.
template <typename F>
std::size_t allocated_by(F&& f) {
  g_allocated = 0;
  g_counting = true;
  f();
  g_counting = false;
  return g_allocated;
}

void put_i32(std::vector<uint8_t>& buf, std::size_t at, int32_t v) {
  const auto u = static_cast<uint32_t>(v);
  for (int i = 0; i < 4; ++i) buf[at + static_cast<std::size_t>(i)] = static_cast<uint8_t>(u >> (24 - 8 * i));
}

// The 20-byte FEATURES of issue 12: fingerprint, utime, num_obs = 1e8, no obs.
std::vector<uint8_t> huge_features() {
  std::vector<uint8_t> buf = sample(vimot_test::sample_features(0)).bytes;
  REQUIRE(buf.size() == 20);
  put_i32(buf, 16, 100000000);
  return buf;
}

}  // namespace

TEST_CASE("every type in lcmtypes/ has a layout matching its generated fingerprint") {
  // vimot_lcm_types() throws if a layout's fingerprint differs from getHash().
  std::set<std::string> covered;
  for (const vimot::LcmTypeInfo& t : vimot::vimot_lcm_types()) {
    covered.insert(t.layout->name);
    for (const vimot::LcmField& f : t.layout->fields) {
      if (f.type != nullptr) covered.insert(f.type->name);  // nested types
    }
  }
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(VIMOT_LCMTYPES_DIR)) {
    const std::string stem = e.path().stem().string();
    if (e.path().extension() == ".lcm") files.insert(stem.substr(std::string("vimot_").size()));
  }
  CHECK(files.size() == 15);
  CHECK(covered == files);
}

TEST_CASE("valid messages of every type pass the length check and decode") {
  for (const Sample& s : all_samples()) {
    INFO(s.type);
    CHECK(lcm_lengths_fit(*vimot::find_lcm_type(s.bytes.data(), static_cast<int>(s.bytes.size()))->layout,
                          s.bytes.data(), static_cast<int>(s.bytes.size())));
    CHECK(s.decodes(s.bytes.data(), static_cast<int>(s.bytes.size())));
  }
  // Empty arrays and a large valid one.
  const Sample empty = sample(vimot_test::sample_features(0));
  CHECK(empty.decodes(empty.bytes.data(), static_cast<int>(empty.bytes.size())));
  const Sample big = sample(vimot_test::sample_features(5000));
  CHECK(big.decodes(big.bytes.data(), static_cast<int>(big.bytes.size())));
}

TEST_CASE("a 20-byte FEATURES claiming 1e8 observations is rejected before the decoder allocates") {
  const std::vector<uint8_t> buf = huge_features();
  bool decoded = true;
  const std::size_t bytes = allocated_by([&] {
    vimot::features_t msg;
    decoded = decode_untrusted(buf.data(), static_cast<int>(buf.size()), &msg);
  });
  CHECK_FALSE(decoded);
  // The walk's own bookkeeping (a count per member), not 1e8 x 48 bytes.
  CHECK(bytes <= 256);
  // The registry (vimot-log-summary) goes through the same check.
  const vimot::LcmTypeInfo* type = vimot::find_lcm_type(buf.data(), static_cast<int>(buf.size()));
  REQUIRE(type != nullptr);
  CHECK(allocated_by([&] { decoded = type->decodes(buf.data(), static_cast<int>(buf.size())); }) <= 256);
  CHECK_FALSE(decoded);
}

TEST_CASE("no corrupted 32-bit field of any type makes the decoder allocate beyond the message size") {
  // Every 4-byte window of every sample is overwritten with lengths a
  // corrupt or hostile sender could claim; whatever the field was, decoding
  // may fail or succeed but must stay within a small multiple of the bytes
  // received (the decoded structs are larger than their encodings: at most
  // sizeof(image_metadata_t) / 9 encoded bytes ~ 8).
  const int32_t lengths[] = {-1, std::numeric_limits<int32_t>::min(), 100000000,
                             std::numeric_limits<int32_t>::max(), 1 << 20};
  int rejected = 0;
  for (const Sample& s : all_samples()) {
    for (std::size_t at = 8; at + 4 <= s.bytes.size(); ++at) {
      for (int32_t len : lengths) {
        std::vector<uint8_t> bad = s.bytes;
        put_i32(bad, at, len);
        bool ok = true;
        const std::size_t bytes = allocated_by([&] { ok = s.decodes(bad.data(), static_cast<int>(bad.size())); });
        if (!ok) ++rejected;
        INFO(s.type << ": " << len << " at byte " << at);
        REQUIRE(bytes <= 16 * bad.size() + 1024);
      }
    }
  }
  CHECK(rejected > 0);
}

TEST_CASE("a subscriber counts the oversized FEATURES as a decode error and never sees it") {
  vimot::Process p("test-proc", "A test process.");
  const char* argv[] = {"test-proc", "--lcm-url", "memq://", "--log-level", "error"};
  REQUIRE(p.init(5, argv));
  int calls = 0;
  p.subscribe<vimot::features_t>("FEATURES", [&](const vimot::features_t&) { ++calls; });
  const std::vector<uint8_t> buf = huge_features();
  for (int i = 0; i < 50; ++i) p.lcm().publish("FEATURES", buf.data(), static_cast<unsigned>(buf.size()));
  const vimot::features_t good = vimot_test::sample_features();
  p.publish("FEATURES", good);
  const std::size_t bytes = allocated_by([&] {
    while (p.lcm().handleTimeout(10) > 0) {
    }
  });
  CHECK(calls == 1);
  CHECK(p.counters().decode_errors == 50);
  CHECK(p.counters().messages_in == 51);
  // 50 x 1e8 x sizeof(feature_obs_t) would be ~ 240 GB.
  CHECK(bytes < (1u << 20));
}

TEST_CASE("vimot-log-summary counts the oversized FEATURES as undecodable instead of dying") {
  const std::string log_path = std::filesystem::temp_directory_path() /
                               ("lcm_layout_test_" + std::to_string(::getpid()) + ".lcmlog");
  {
    lcm::LogFile log(log_path, "w");
    REQUIRE(log.good());
    std::vector<uint8_t> buf = huge_features();
    const Sample good = sample(vimot_test::sample_features());
    int64_t t = 1;
    for (const std::vector<uint8_t>* b : std::vector<const std::vector<uint8_t>*>{&buf, &good.bytes, &buf}) {
      lcm::LogEvent ev{};
      ev.timestamp = t++;
      ev.channel = "FEATURES";
      ev.datalen = static_cast<int32_t>(b->size());
      ev.data = const_cast<uint8_t*>(b->data());
      REQUIRE(log.writeEvent(&ev) == 0);
    }
  }
  const std::string out_path = log_path + ".txt";
  const int status = std::system((std::string(VIMOT_LOG_SUMMARY) + " " + log_path + " > " + out_path + " 2>&1").c_str());
  REQUIRE(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 2);  // "exits 2 if any vimot message fails to decode"
  std::ifstream in(out_path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  INFO(text);
  // channel, type, 3 messages, rate, kB, 2 undecodable
  CHECK(text.find("vimot.features_t") != std::string::npos);
  CHECK(text.find("2\n") != std::string::npos);
  std::filesystem::remove(log_path);
  std::filesystem::remove(out_path);
}

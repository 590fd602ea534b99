#pragma once
// Catch helpers for the LCM type tests: encoding to bytes and a round trip
// through a real in-memory LCM (memq://).

#include <catch2/catch.hpp>
#include <lcm/lcm-cpp.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "lcmtypes_samples.h"

namespace vimot_test {

/// A C array as a vector, so Catch compares it element-wise and prints both.
template <typename T, std::size_t N>
std::vector<T> vec(const T (&a)[N]) {
  return std::vector<T>(a, a + N);
}

template <typename Msg>
std::vector<uint8_t> encode(const Msg& msg) {
  std::vector<uint8_t> buf(static_cast<std::size_t>(msg.getEncodedSize()));
  const int n = msg.encode(buf.data(), 0, static_cast<int>(buf.size()));
  REQUIRE(n == static_cast<int>(buf.size()));
  return buf;
}

template <typename Msg>
class Receiver {
 public:
  void on_message(const lcm::ReceiveBuffer* /*rbuf*/, const std::string& channel,
                  const Msg* msg) {
    ++count;
    last_channel = channel;
    last = *msg;
  }
  int count{0};
  std::string last_channel;
  Msg last{};
};

/// Publishes `sent` through a real in-memory LCM and returns what a typed
/// subscriber received, checking exactly one message arrived on the channel.
template <typename Msg>
Msg publish_and_receive(const Msg& sent) {
  lcm::LCM lcm("memq://");
  REQUIRE(lcm.good());
  const std::string channel = std::string("TEST_") + Msg::getTypeName();
  Receiver<Msg> rx;
  // memq drops messages on channels nobody subscribes to: subscribe first.
  REQUIRE(lcm.subscribe(channel, &Receiver<Msg>::on_message, &rx) != nullptr);
  REQUIRE(lcm.publish(channel, &sent) == 0);
  REQUIRE(lcm.handleTimeout(1000) > 0);
  REQUIRE(rx.count == 1);
  REQUIRE(rx.last_channel == channel);
  REQUIRE(lcm.handleTimeout(0) == 0);  // nothing else queued
  return rx.last;
}

}  // namespace vimot_test

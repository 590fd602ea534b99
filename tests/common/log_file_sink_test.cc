// LogFileSink's append mode (a respawned vimot-logger goes on with the run's
// record): a half-written last event left by a killed writer is cut, so
// every event written after it reads back whole with LCM's own reader.
#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "common/process/event_sink.h"

namespace {

using vimot::LogFileSink;

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("vimot_log_file_sink_test_" + name)).string();
}

std::string bytes_of(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void append_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::app) << bytes;
}

void write_events(LogFileSink& sink, int first, int count) {
  for (int i = first; i < first + count; ++i) {
    const std::string data = "payload " + std::to_string(i);
    sink.write("CH" + std::to_string(i), 1000 + i, data.data(), static_cast<int>(data.size()));
  }
}

struct ReadEvent {
  int64_t timestamp;
  std::string channel;
  std::string data;
};

// Every event LCM's reader gives.
std::vector<ReadEvent> read_all(const std::string& path) {
  lcm::LogFile log(path, "r");
  REQUIRE(log.good());
  std::vector<ReadEvent> out;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    out.push_back({e->timestamp, e->channel,
                   std::string(static_cast<const char*>(e->data), static_cast<std::size_t>(e->datalen))});
  }
  return out;
}

// The bytes of one event written alone (header 28 + channel + data).
std::string one_event_bytes(int i) {
  const std::string path = temp_path("one");
  {
    LogFileSink sink(path);
    write_events(sink, i, 1);
  }
  const std::string bytes = bytes_of(path);
  std::remove(path.c_str());
  return bytes;
}

}  // namespace

TEST_CASE("scan_log_file counts whole events and sees a half-written last one") {
  const std::string path = temp_path("scan");
  {
    LogFileSink sink(path);
    write_events(sink, 0, 3);
  }
  const int64_t whole = static_cast<int64_t>(std::filesystem::file_size(path));
  vimot::LogFileTail tail = vimot::scan_log_file(path);
  CHECK(tail.events == 3);
  CHECK(tail.complete_bytes == whole);
  CHECK(tail.file_bytes == whole);

  const std::string fourth = one_event_bytes(3);
  REQUIRE(fourth.size() == 28 + 3 + 9);  // "CH3", "payload 3"
  append_bytes(path, fourth.substr(0, 30));  // killed inside the channel name
  tail = vimot::scan_log_file(path);
  CHECK(tail.events == 3);
  CHECK(tail.complete_bytes == whole);
  CHECK(tail.file_bytes == whole + 30);

  CHECK(vimot::scan_log_file(temp_path("missing")).file_bytes == 0);
  std::remove(path.c_str());
}

TEST_CASE("appending after a killed writer: the half event is cut, every event reads back whole") {
  const std::string path = temp_path("append");
  std::remove(path.c_str());
  {
    LogFileSink sink(path);
    write_events(sink, 0, 3);
  }
  const int64_t whole = static_cast<int64_t>(std::filesystem::file_size(path));
  append_bytes(path, one_event_bytes(3).substr(0, 33));  // inside the data

  {
    LogFileSink sink(path, LogFileSink::Mode::kAppend);
    CHECK(sink.found().events == 3);
    CHECK(sink.found().complete_bytes == whole);
    CHECK(sink.found().file_bytes == whole + 33);
    write_events(sink, 4, 2);
  }
  const std::vector<ReadEvent> events = read_all(path);
  REQUIRE(events.size() == 5);
  const int written[] = {0, 1, 2, 4, 5};
  for (std::size_t k = 0; k < events.size(); ++k) {
    CHECK(events[k].timestamp == 1000 + written[k]);
    CHECK(events[k].channel == "CH" + std::to_string(written[k]));
    CHECK(events[k].data == "payload " + std::to_string(written[k]));
  }
  std::remove(path.c_str());
}

TEST_CASE("append to a missing file starts it; replace mode replaces") {
  const std::string path = temp_path("fresh");
  std::remove(path.c_str());
  {
    LogFileSink sink(path, LogFileSink::Mode::kAppend);
    CHECK(sink.found().file_bytes == 0);
    write_events(sink, 0, 2);
  }
  CHECK(read_all(path).size() == 2);
  {
    LogFileSink sink(path);
    write_events(sink, 7, 1);
  }
  const std::vector<ReadEvent> events = read_all(path);
  REQUIRE(events.size() == 1);
  CHECK(events[0].channel == "CH7");
  std::remove(path.c_str());
}

TEST_CASE("garbage between events is skipped as LCM's reader does") {
  const std::string path = temp_path("garbage");
  {
    LogFileSink sink(path);
    write_events(sink, 0, 2);
  }
  append_bytes(path, std::string("\x01\x02\xED\xA1\x00garbage", 12));
  append_bytes(path, one_event_bytes(2));
  const vimot::LogFileTail tail = vimot::scan_log_file(path);
  CHECK(tail.events == 3);
  CHECK(tail.complete_bytes == tail.file_bytes);
  std::remove(path.c_str());
}

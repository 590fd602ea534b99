#pragma once
// A MIP device on the master side of a pseudo-terminal, for driver tests: it
// answers the set-up commands (ACK, or a NACK / silence when told to), and
// once resumed streams generated IMU packets in real time with faults:
// garbage before some packets, a flipped byte in some, truncated frames,
// packets written in two pieces. unplug() closes the master (the driver's
// slave side hangs up); plug() makes a new pty pair, as a USB re-plug would.
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdlib.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "drivers/imu_mip/mip_messages.h"
#include "drivers/imu_mip/mip_parser.h"
#include "tests/imu_mip/mip_test_packets.h"

namespace vimot::mip::test {

class SimulatedMipDevice {
 public:
  struct Behaviour {
    uint16_t base_rate{1000};      // Hz, reported to the base-rate query
    uint8_t nack_command{0};       // 3DM command answered with a NACK (0: none)
    uint8_t nack_code{0x03};
    uint8_t ignore_once_command{0};  // base command left unanswered the first time
    int initial_packets{0};        // stale data waiting in the pty when the driver opens
  };

  /// What was sent, for the test's expectations.
  struct Sent {
    std::vector<int> good;         // sample indices of intact packets, in order
    int64_t dropped_bytes{0};      // garbage + corrupted + truncated bytes
    int corrupted{0};
    int truncated{0};
  };

  explicit SimulatedMipDevice(const Behaviour& b) : behaviour_(b) {
    plug();
    thread_ = std::thread([this] { loop(); });
  }

  ~SimulatedMipDevice() {
    stop_ = true;
    thread_.join();
    std::lock_guard<std::mutex> lock(mutex_);
    close_fds();
  }

  void plug() {
    std::lock_guard<std::mutex> lock(mutex_);
    // Non-blocking, so a full pty never blocks this thread while it holds the
    // lock the test thread (which also runs the reading driver) needs.
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0) throw std::runtime_error("posix_openpt");
    char name[128];
    if (ptsname_r(master_, name, sizeof name) != 0) throw std::runtime_error("ptsname_r");
    slave_path_ = name;
    // Hold a slave fd so the master never reads a hang-up while the driver
    // is between opens; raw mode so nothing is echoed or translated.
    keep_slave_ = ::open(name, O_RDWR | O_NOCTTY);
    termios tio{};
    tcgetattr(keep_slave_, &tio);
    cfmakeraw(&tio);
    tcsetattr(keep_slave_, TCSANOW, &tio);
    parser_.reset();
    streaming_ = true;  // a device powers up streaming its last configuration
    for (int i = 0; i < behaviour_.initial_packets; ++i) write_all(test_packet(100000 + i));
    plugged_ = true;
  }

  void unplug() {
    std::lock_guard<std::mutex> lock(mutex_);
    close_fds();
    plugged_ = false;
  }

  /// Path of the current slave; throws when unplugged (the opener's failure).
  std::string slave_path() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!plugged_) throw std::runtime_error("no device");
    return slave_path_;
  }

  /// Streams n more packets once the driver has resumed the device.
  void stream(int n) { to_send_ += n; }
  /// Streams these bytes (e.g. a recording) once resumed, as fast as the pty takes them.
  void stream_bytes(const std::vector<uint8_t>& bytes) {
    std::lock_guard<std::mutex> lock(mutex_);
    raw_.insert(raw_.end(), bytes.begin(), bytes.end());
  }
  bool idle_to_send() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return to_send_ == 0 && raw_sent_ == raw_.size();
  }

  std::vector<std::pair<uint8_t, uint8_t>> commands() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return commands_;
  }
  std::vector<uint8_t> last_format() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return format_;
  }
  Sent sent() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return sent_;
  }

 private:
  void close_fds() {
    if (master_ >= 0) ::close(master_);
    if (keep_slave_ >= 0) ::close(keep_slave_);
    master_ = keep_slave_ = -1;
  }

  void write_all(const std::vector<uint8_t>& bytes) {
    std::size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::write(master_, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno != EAGAIN && errno != EINTR) return;
      if (n > 0) done += static_cast<std::size_t>(n);
    }
  }

  void answer(const MipPacket& cmd) {
    if (cmd.fields.empty()) return;
    const uint8_t set = cmd.descriptor_set;
    const uint8_t c = cmd.fields[0].descriptor;
    commands_.emplace_back(set, c);
    if (set == kBaseCommandSet && c == behaviour_.ignore_once_command && !ignored_once_) {
      ignored_once_ = true;
      return;
    }
    if (set == k3dmCommandSet && c == behaviour_.nack_command) {
      write_all(ack_packet(set, c, behaviour_.nack_code));
      return;
    }
    if (set == kBaseCommandSet && c == kCmdIdle) streaming_ = false;
    if (set == kBaseCommandSet && c == kCmdResume) streaming_ = true;
    if (set == k3dmCommandSet && c == kCmdImuMessageFormat) {
      format_.assign(cmd.data(cmd.fields[0]), cmd.data(cmd.fields[0]) + cmd.fields[0].size);
    }
    std::vector<FieldSpec> extra;
    if (set == k3dmCommandSet && c == kCmdGetImuBaseRate) {
      FieldSpec rate{kReplyImuBaseRate, {}};
      append_u16(rate.data, behaviour_.base_rate);
      extra.push_back(rate);
    }
    write_all(ack_packet(set, c, 0, extra));
  }

  // Faults by sample index, so the test knows what arrives intact.
  void send_sample(int k) {
    std::vector<uint8_t> packet = test_packet(k, 200.0);
    if (k % 10 == 3) {
      std::vector<uint8_t> garbage(static_cast<std::size_t>(1 + k % 29));
      for (std::size_t i = 0; i < garbage.size(); ++i) garbage[i] = static_cast<uint8_t>((i * 37 + k) % 0x70);
      write_all(garbage);
      sent_.dropped_bytes += static_cast<int64_t>(garbage.size());
    }
    if (k % 25 == 7) {
      packet[10] ^= 0x20;
      ++sent_.corrupted;
      sent_.dropped_bytes += static_cast<int64_t>(packet.size());
    } else if (k % 50 == 40) {
      packet.resize(15);
      ++sent_.truncated;
      sent_.dropped_bytes += 15;
    } else {
      sent_.good.push_back(k);
    }
    if (k % 7 == 2) {
      const std::size_t half = packet.size() / 2;
      write_all(std::vector<uint8_t>(packet.begin(), packet.begin() + static_cast<std::ptrdiff_t>(half)));
      mutex_.unlock();
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
      mutex_.lock();
      if (master_ < 0) return;
      write_all(std::vector<uint8_t>(packet.begin() + static_cast<std::ptrdiff_t>(half), packet.end()));
    } else {
      write_all(packet);
    }
  }

  void loop() {
    using Clock = std::chrono::steady_clock;
    auto next_sample = Clock::now();
    std::vector<uint8_t> buffer(512);
    while (!stop_) {
      std::unique_lock<std::mutex> lock(mutex_);
      if (master_ < 0) {
        lock.unlock();
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      pollfd pfd{master_, POLLIN, 0};
      if (::poll(&pfd, 1, 0) > 0 && (pfd.revents & POLLIN)) {
        const ssize_t n = ::read(master_, buffer.data(), buffer.size());
        if (n > 0) parser_.feed(buffer.data(), static_cast<std::size_t>(n));
        MipPacket cmd;
        while (parser_.next(cmd)) answer(cmd);
      }
      const bool resumed = streaming_ && !format_.empty();
      if (resumed && raw_sent_ < raw_.size()) {
        const ssize_t n = ::write(master_, raw_.data() + raw_sent_, std::min<std::size_t>(1024, raw_.size() - raw_sent_));
        if (n > 0) raw_sent_ += static_cast<std::size_t>(n);
      }
      if (resumed && to_send_ > 0 && Clock::now() >= next_sample) {
        send_sample(next_k_++);
        --to_send_;
        next_sample = Clock::now() + std::chrono::milliseconds(5);  // 200 Hz
      }
      lock.unlock();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  }

  Behaviour behaviour_;
  mutable std::mutex mutex_;
  int master_{-1};
  int keep_slave_{-1};
  std::string slave_path_;
  bool plugged_{false};
  bool streaming_{false};
  bool ignored_once_{false};
  MipParser parser_;
  std::vector<std::pair<uint8_t, uint8_t>> commands_;
  std::vector<uint8_t> format_;
  Sent sent_;
  int next_k_{0};
  std::vector<uint8_t> raw_;
  std::size_t raw_sent_{0};
  std::atomic<int> to_send_{0};
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace vimot::mip::test

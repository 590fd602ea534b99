// ByteStream over a raw file descriptor (pseudo-terminals in tests, or any
// tty libserialport will not open).
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstring>

#include "drivers/imu_mip/byte_stream.h"

namespace vimot::mip {

namespace {

speed_t to_speed(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 921600: return B921600;
    default: throw std::invalid_argument("unsupported baud rate " + std::to_string(baud));
  }
}

class TtyFdStream : public ByteStream {
 public:
  TtyFdStream(const std::string& path, int baud) : path_(path) {
    const speed_t speed = to_speed(baud);
    fd_ = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) throw std::runtime_error("cannot open '" + path + "': " + std::strerror(errno));
    termios tio{};
    if (tcgetattr(fd_, &tio) == 0) {
      cfmakeraw(&tio);
      cfsetispeed(&tio, speed);
      cfsetospeed(&tio, speed);
      tcsetattr(fd_, TCSANOW, &tio);  // best effort: a pty ignores the speed
    }
  }

  ~TtyFdStream() override { ::close(fd_); }

  std::size_t read(uint8_t* data, std::size_t size, int timeout_ms) override {
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, timeout_ms);
    if (ready < 0) {
      if (errno == EINTR) return 0;
      throw StreamClosed("poll failed on '" + path_ + "': " + std::strerror(errno));
    }
    if (ready == 0) return 0;
    const ssize_t n = ::read(fd_, data, size);
    if (n > 0) return static_cast<std::size_t>(n);
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) return 0;
    // EOF, or EIO on a pty slave whose master closed.
    throw StreamClosed("hang-up on '" + path_ + "'" + (n < 0 ? std::string(": ") + std::strerror(errno) : ""));
  }

  void write(const uint8_t* data, std::size_t size, int timeout_ms) override {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    std::size_t done = 0;
    while (done < size) {
      const int left_ms = static_cast<int>(
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count());
      pollfd pfd{fd_, POLLOUT, 0};
      if (left_ms <= 0 || ::poll(&pfd, 1, left_ms) <= 0 || (pfd.revents & (POLLHUP | POLLERR))) {
        throw StreamClosed("write failed on '" + path_ + "' (" + std::to_string(done) + " of " +
                           std::to_string(size) + " bytes)");
      }
      const ssize_t n = ::write(fd_, data + done, size - done);
      if (n < 0 && errno != EAGAIN && errno != EINTR) {
        throw StreamClosed("write failed on '" + path_ + "': " + std::strerror(errno));
      }
      if (n > 0) done += static_cast<std::size_t>(n);
    }
  }

 private:
  std::string path_;
  int fd_{-1};
};

}  // namespace

std::unique_ptr<ByteStream> open_tty_fd(const std::string& path, int baud) {
  return std::make_unique<TtyFdStream>(path, baud);
}

}  // namespace vimot::mip

#pragma once
// The byte pipe under the MIP driver, so the same driver runs on a serial
// device (libserialport) and on a pseudo-terminal in tests (a raw fd):
// Debian 12's libserialport 0.1.1 cannot open a pty (sp_get_port_by_name
// wants a /sys/class/tty entry, and TIOCMGET fails on a pty slave).

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

namespace vimot::mip {

/// The device went away (unplugged, hung up); the driver reopens.
class StreamClosed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class ByteStream {
 public:
  virtual ~ByteStream() = default;
  /// Reads up to `size` bytes, waiting at most `timeout_ms` for the first;
  /// 0 on timeout. Throws StreamClosed on hang-up or a read error.
  virtual std::size_t read(uint8_t* data, std::size_t size, int timeout_ms) = 0;
  /// Writes all bytes within `timeout_ms`; throws StreamClosed otherwise.
  virtual void write(const uint8_t* data, std::size_t size, int timeout_ms) = 0;
};

/// Opens the stream (throws std::runtime_error when the device is absent).
using StreamOpener = std::function<std::unique_ptr<ByteStream>()>;

/// A serial device through libserialport, 8N1, no flow control.
std::unique_ptr<ByteStream> open_serial_port(const std::string& port, int baud);

/// Any file descriptor-backed tty (pseudo-terminal slave, serial device):
/// opened non-blocking, raw mode, `baud` set when the tty accepts it.
std::unique_ptr<ByteStream> open_tty_fd(const std::string& path, int baud);

}  // namespace vimot::mip

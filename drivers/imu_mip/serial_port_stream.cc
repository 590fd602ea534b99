// ByteStream over libserialport (Debian 12: 0.1.1).
#include <libserialport.h>

#include <algorithm>

#include "drivers/imu_mip/byte_stream.h"

namespace vimot::mip {

namespace {

std::string sp_error_text(const std::string& what, const std::string& port) {
  char* msg = sp_last_error_message();
  std::string text = what + " '" + port + "': " + (msg ? msg : "unknown error");
  if (msg) sp_free_error_message(msg);
  return text;
}

class SerialPortStream : public ByteStream {
 public:
  SerialPortStream(const std::string& name, int baud) : name_(name) {
    if (sp_get_port_by_name(name.c_str(), &port_) != SP_OK) {
      throw std::runtime_error(sp_error_text("no serial port", name));
    }
    if (sp_open(port_, SP_MODE_READ_WRITE) != SP_OK) {
      const std::string text = sp_error_text("cannot open serial port", name);
      sp_free_port(port_);
      throw std::runtime_error(text);
    }
    if (sp_set_baudrate(port_, baud) != SP_OK || sp_set_bits(port_, 8) != SP_OK ||
        sp_set_parity(port_, SP_PARITY_NONE) != SP_OK || sp_set_stopbits(port_, 1) != SP_OK ||
        sp_set_flowcontrol(port_, SP_FLOWCONTROL_NONE) != SP_OK) {
      const std::string text = sp_error_text("cannot configure " + std::to_string(baud) + " 8N1 on", name);
      sp_close(port_);
      sp_free_port(port_);
      throw std::runtime_error(text);
    }
  }

  ~SerialPortStream() override {
    sp_close(port_);
    sp_free_port(port_);
  }

  std::size_t read(uint8_t* data, std::size_t size, int timeout_ms) override {
    // libserialport's timeout 0 means "wait forever": a zero wait polls instead.
    const sp_return n = timeout_ms > 0 ? sp_blocking_read(port_, data, size, static_cast<unsigned>(timeout_ms))
                                       : sp_nonblocking_read(port_, data, size);
    if (n < 0) throw StreamClosed(sp_error_text("read failed on", name_));
    // 0.1.1 reports a hang-up as a timeout; the input queue query fails then.
    if (n == 0 && sp_input_waiting(port_) < 0) throw StreamClosed(sp_error_text("hang-up on", name_));
    return static_cast<std::size_t>(n);
  }

  void write(const uint8_t* data, std::size_t size, int timeout_ms) override {
    const sp_return n = sp_blocking_write(port_, data, size, static_cast<unsigned>(std::max(timeout_ms, 1)));
    if (n < 0) throw StreamClosed(sp_error_text("write failed on", name_));
    if (static_cast<std::size_t>(n) != size) {
      throw StreamClosed("write timed out on '" + name_ + "' (" + std::to_string(n) + " of " +
                         std::to_string(size) + " bytes)");
    }
  }

 private:
  std::string name_;
  sp_port* port_{nullptr};
};

}  // namespace

std::unique_ptr<ByteStream> open_serial_port(const std::string& port, int baud) {
  return std::make_unique<SerialPortStream>(port, baud);
}

}  // namespace vimot::mip

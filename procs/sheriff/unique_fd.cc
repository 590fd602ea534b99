#include "procs/sheriff/unique_fd.h"

#include <unistd.h>

#include <utility>

namespace vimot::sheriff {

UniqueFd::~UniqueFd() { reset(); }

UniqueFd::UniqueFd(UniqueFd&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)) {}

UniqueFd& UniqueFd::operator=(UniqueFd&& other) noexcept {
  if (this != &other) {
    reset();
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

void UniqueFd::reset() {
  if (fd_ >= 0) {
    // close() may report EINTR, but on Linux the descriptor is released
    // anyway; retrying could close a descriptor another thread just opened.
    ::close(fd_);
    fd_ = -1;
  }
}

}  // namespace vimot::sheriff

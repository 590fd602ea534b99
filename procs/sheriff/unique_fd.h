#pragma once

namespace vimot::sheriff {

/// Owns one POSIX file descriptor and closes it on destruction, so pipe ends
/// are never leaked on an early return or an exception. Move-only.
class UniqueFd {
 public:
  UniqueFd() = default;
  /// Takes ownership of `fd` (-1 means "no descriptor").
  explicit UniqueFd(int fd) : fd_(fd) {}
  ~UniqueFd();

  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  UniqueFd(UniqueFd&& other) noexcept;
  UniqueFd& operator=(UniqueFd&& other) noexcept;

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }

  /// Closes the descriptor now (no-op when there is none).
  void reset();

 private:
  int fd_{-1};
};

}  // namespace vimot::sheriff

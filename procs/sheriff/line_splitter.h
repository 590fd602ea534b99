#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace vimot::sheriff {

/// Reassembles lines from the arbitrary chunks a pipe read returns, so a
/// child's output is printed one whole line at a time with its prefix.
class LineSplitter {
 public:
  /// A line longer than this many bytes is emitted in pieces of this size, so
  /// a child that never writes '\n' cannot grow the sheriff's memory without
  /// bound.
  static constexpr std::size_t kDefaultMaxLineLength = 64 * 1024;

  explicit LineSplitter(std::size_t max_line_length = kDefaultMaxLineLength);

  /// Appends `bytes` and returns every line completed by them, without the
  /// '\n' (and without a '\r' just before it).
  std::vector<std::string> Append(std::string_view bytes);

  /// Returns the unterminated remainder (if any) and clears it; called when
  /// the stream ends so a last line without '\n' is not lost.
  std::optional<std::string> Flush();

 private:
  std::size_t max_line_length_{kDefaultMaxLineLength};
  std::string partial_;
};

}  // namespace vimot::sheriff

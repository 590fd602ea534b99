#include "procs/sheriff/line_splitter.h"

#include <stdexcept>

namespace vimot::sheriff {

namespace {
std::string StripCarriageReturn(std::string line) {
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}
}  // namespace

LineSplitter::LineSplitter(std::size_t max_line_length)
    : max_line_length_(max_line_length) {
  if (max_line_length_ == 0) {
    throw std::invalid_argument("LineSplitter: max_line_length must be > 0");
  }
}

std::vector<std::string> LineSplitter::Append(std::string_view bytes) {
  std::vector<std::string> lines;
  for (const char c : bytes) {
    if (c == '\n') {
      lines.push_back(StripCarriageReturn(std::move(partial_)));
      partial_.clear();
      continue;
    }
    partial_.push_back(c);
    if (partial_.size() >= max_line_length_) {
      lines.push_back(std::move(partial_));
      partial_.clear();
    }
  }
  return lines;
}

std::optional<std::string> LineSplitter::Flush() {
  if (partial_.empty()) return std::nullopt;
  std::string rest = StripCarriageReturn(std::move(partial_));
  partial_.clear();
  return rest;
}

}  // namespace vimot::sheriff

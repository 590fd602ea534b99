// Reassembling lines from pipe chunks.
#include <catch2/catch.hpp>

#include "procs/sheriff/line_splitter.h"

using namespace vimot::sheriff;
using Lines = std::vector<std::string>;

TEST_CASE("lines split across chunks are reassembled") {
  LineSplitter s;
  CHECK(s.Append("he").empty());
  CHECK(s.Append("llo\nwor") == Lines{"hello"});
  CHECK(s.Append("ld\r\n\nlast") == Lines{"world", ""});
  CHECK(s.Flush() == std::optional<std::string>("last"));
  CHECK_FALSE(s.Flush().has_value());
}

TEST_CASE("an endless line is cut at the maximum length") {
  LineSplitter s(4);
  CHECK(s.Append("abcdefghij") == Lines{"abcd", "efgh"});
  CHECK(s.Flush() == std::optional<std::string>("ij"));
  CHECK_THROWS_AS(LineSplitter(0), std::invalid_argument);
}

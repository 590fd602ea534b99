#include <catch2/catch.hpp>

#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "common/process/arg_parser.h"

using vimot::ArgError;
using vimot::ArgParser;

namespace {
// What run_main prints to std::cerr and returns for a run that throws `error`.
std::string run_main_message(int* status, void (*error)()) {
  static void (*thrower)() = nullptr;
  thrower = error;
  std::ostringstream err;
  std::streambuf* const saved = std::cerr.rdbuf(err.rdbuf());
  char arg0[] = "vimot-test";
  char* argv[] = {arg0, nullptr};
  *status = vimot::run_main("vimot-test", 1, argv, [](int, const char* const*) -> int {
    thrower();
    return 0;
  });
  std::cerr.rdbuf(saved);
  return err.str();
}

ArgParser make_parser() {
  ArgParser p("vimot-test", "A test program.");
  p.add_option("speed", "FACTOR", "playback speed", "1.0");
  p.add_option("seed", "N", "random seed", "7");
  p.add_flag("quiet", "less output");
  p.set_positional("[LOG]", "log file", 0, 1);
  return p;
}
}  // namespace

TEST_CASE("options, flags, defaults and positionals parse") {
  ArgParser p = make_parser();
  const char* argv[] = {"prog", "--speed", "2.5", "--quiet", "out.lcm", "--seed=42"};
  REQUIRE(p.parse(6, argv));
  CHECK(p.get_double("speed") == 2.5);
  CHECK(p.get_int("seed") == 42);
  CHECK(p.flag("quiet"));
  REQUIRE(p.positionals().size() == 1);
  CHECK(p.positionals()[0] == "out.lcm");

  ArgParser q = make_parser();
  const char* bare[] = {"prog"};
  REQUIRE(q.parse(1, bare));
  CHECK(q.get_double("speed") == 1.0);
  CHECK_FALSE(q.flag("quiet"));
}

TEST_CASE("--help returns false and usage lists every option") {
  ArgParser p = make_parser();
  const char* argv[] = {"prog", "--help"};
  CHECK_FALSE(p.parse(2, argv));
  const std::string u = p.usage();
  CHECK(u.find("--speed FACTOR") != std::string::npos);
  CHECK(u.find("(default: 1.0)") != std::string::npos);
  CHECK(u.find("--quiet") != std::string::npos);
}

TEST_CASE("bad arguments name what was wrong") {
  auto fails_with = [](std::vector<const char*> argv, const std::string& expected) {
    ArgParser p = make_parser();
    try {
      p.parse(static_cast<int>(argv.size()), argv.data());
      p.get_double("speed");
      p.get_int("seed");
    } catch (const ArgError& e) {
      return std::string(e.what()).find(expected) != std::string::npos;
    }
    return false;
  };
  CHECK(fails_with({"prog", "--sped", "2"}, "unknown option '--sped'"));
  CHECK(fails_with({"prog", "--speed"}, "--speed needs a FACTOR"));
  CHECK(fails_with({"prog", "--speed", "fast"}, "--speed must be a finite number, got 'fast'"));
  CHECK(fails_with({"prog", "--speed", "nan"}, "finite number"));
  CHECK(fails_with({"prog", "--seed", "4.2"}, "--seed must be an integer"));
  CHECK(fails_with({"prog", "a.lcm", "b.lcm"}, "expected 0 to 1 positional"));
  CHECK(fails_with({"prog", "--quiet=yes"}, "takes no value"));
}

TEST_CASE("run_main names the program once") {
  int status = 0;
  // ArgParser's errors carry the program's name already.
  CHECK(run_main_message(&status, [] {
          const char* argv[] = {"vimot-test", "--sped", nullptr};
          make_parser().parse(2, argv);
        }) == "vimot-test: unknown option '--sped' (see --help)\n");
  CHECK(status == 1);
  CHECK(run_main_message(&status, [] { throw std::runtime_error("--duration must be > 0"); }) ==
        "vimot-test: --duration must be > 0\n");
  CHECK(status == 1);
}

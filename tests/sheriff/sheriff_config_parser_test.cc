// The procman config parser: every field of a representative config, the
// script actions, and error messages that point at line and column.
#include <catch2/catch.hpp>

#include <string>

#include "procs/sheriff/sheriff_config_parser.h"

using namespace vimot::sheriff;
using std::chrono::milliseconds;

namespace {

// Shaped like a real bring-up file: numbered groups in start order, nested
// groups, top-level commands, a cmd placed by its group attribute, scripts
// that call each other, comments everywhere.
constexpr char kConfig[] = R"(# vimot demo bring-up
group "0.sensors" {
  # the simulator publishes camera and IMU
  cmd "sim" {
    exec = "${VIMOT_BIN}/vimot-sim --speed 2";
    host = "localhost";
    auto_respawn = "true";
    stop_signal = 15;
    stop_time_allowed = 5;
  }
  group "imu" {
    cmd "imu-filter" { exec = "$VIMOT_BIN/imu-filter"; priority = 3; }
  }
}
cmd "logger" { exec = "lcm-logger -f \"out dir/out.lcm\""; host = "localhost"; }  # trailing comment
cmd "viewer" { exec = "viewer"; host = "laptop"; group = "2.ui/tools"; }
script "start_all" {
  start group "0.sensors";
  wait ms 500;
  start cmd "logger" wait "running";
  stop cmd "logger";
  wait cmd "sim" status "stopped";
  run_script "other";
}
script "other" {
  restart group "0.sensors/imu" wait "stopped";
  wait group "0.sensors" status "running";
  stop everything;
}
)";

// The error a config text produces; fails the test if it parses.
ConfigParseError ParseError(const std::string& text) {
  try {
    ParseSheriffConfig(text, "bad.pmd");
  } catch (const ConfigParseError& e) {
    return e;
  }
  FAIL("expected a ConfigParseError for:\n" << text);
  throw std::logic_error("unreachable");
}

}  // namespace

TEST_CASE("a representative config parses into every field") {
  const SheriffConfig config = ParseSheriffConfig(kConfig, "demo.pmd");

  REQUIRE(config.commands().size() == 4);
  const CommandSpec& sim = config.commands()[0];
  CHECK(sim.name == "sim");
  CHECK(sim.exec == "${VIMOT_BIN}/vimot-sim --speed 2");
  CHECK(sim.host == "localhost");
  CHECK(sim.group == "0.sensors");
  CHECK(sim.auto_respawn);
  CHECK(sim.stop_signal == 15);
  CHECK(sim.stop_time_allowed == milliseconds(5000));
  CHECK(sim.extra_attributes.empty());
  CHECK(sim.location.file == "demo.pmd");
  CHECK(sim.location.line == 4);
  CHECK(sim.location.column == 7);

  const CommandSpec& imu = config.commands()[1];
  CHECK(imu.name == "imu-filter");
  CHECK(imu.group == "0.sensors/imu");
  CHECK(imu.host == "localhost");  // Default.
  CHECK_FALSE(imu.auto_respawn);
  CHECK(imu.stop_signal == kDefaultStopSignal);
  CHECK(imu.stop_time_allowed == kDefaultStopTimeAllowed);
  REQUIRE(imu.extra_attributes.size() == 1);
  CHECK(imu.extra_attributes[0].first == "priority");
  CHECK(imu.extra_attributes[0].second == "3");

  const CommandSpec& logger = config.commands()[2];
  CHECK(logger.exec == "lcm-logger -f \"out dir/out.lcm\"");
  CHECK(logger.group.empty());

  const CommandSpec& viewer = config.commands()[3];
  CHECK(viewer.host == "laptop");
  CHECK(viewer.group == "2.ui/tools");

  // Groups in order of first appearance, parents before children.
  REQUIRE(config.groups().size() == 4);
  CHECK(config.groups()[0].name == "0.sensors");
  CHECK(config.groups()[0].commands == std::vector<std::string>{"sim"});
  CHECK(config.groups()[0].subgroups == std::vector<std::string>{"0.sensors/imu"});
  CHECK(config.groups()[1].name == "0.sensors/imu");
  CHECK(config.groups()[1].commands == std::vector<std::string>{"imu-filter"});
  CHECK(config.groups()[2].name == "2.ui");
  CHECK(config.groups()[3].name == "2.ui/tools");
  CHECK(config.CommandsInGroup("0.sensors") ==
        std::vector<std::string>{"sim", "imu-filter"});
  CHECK(config.CommandsInGroup("/0.sensors/imu/") ==
        std::vector<std::string>{"imu-filter"});
  CHECK_THROWS_AS(config.CommandsInGroup("0.sensor"), std::invalid_argument);

  REQUIRE(config.scripts().size() == 2);
  const ScriptSpec& start_all = config.scripts()[0];
  CHECK(start_all.name == "start_all");
  REQUIRE(start_all.actions.size() == 6);
  const auto& a = start_all.actions;
  CHECK(a[0].kind == ActionKind::kStart);
  CHECK(a[0].target == ActionTarget::kGroup);
  CHECK(a[0].name == "0.sensors");
  CHECK(a[0].wait == WaitStatus::kNone);
  CHECK(a[0].location.line == 18);
  CHECK(a[0].location.column == 3);
  CHECK(a[1].kind == ActionKind::kWaitMs);
  CHECK(a[1].delay == milliseconds(500));
  CHECK(a[2].kind == ActionKind::kStart);
  CHECK(a[2].target == ActionTarget::kCommand);
  CHECK(a[2].name == "logger");
  CHECK(a[2].wait == WaitStatus::kRunning);
  CHECK(a[3].kind == ActionKind::kStop);
  CHECK(a[3].name == "logger");
  CHECK(a[3].wait == WaitStatus::kNone);
  CHECK(a[4].kind == ActionKind::kWaitStatus);
  CHECK(a[4].target == ActionTarget::kCommand);
  CHECK(a[4].name == "sim");
  CHECK(a[4].wait == WaitStatus::kStopped);
  CHECK(a[5].kind == ActionKind::kRunScript);
  CHECK(a[5].name == "other");

  const auto& b = config.scripts()[1].actions;
  REQUIRE(b.size() == 3);
  CHECK(b[0].kind == ActionKind::kRestart);
  CHECK(b[0].target == ActionTarget::kGroup);
  CHECK(b[0].name == "0.sensors/imu");
  CHECK(b[0].wait == WaitStatus::kStopped);
  CHECK(b[1].kind == ActionKind::kWaitStatus);
  CHECK(b[1].target == ActionTarget::kGroup);
  CHECK(b[1].wait == WaitStatus::kRunning);
  CHECK(b[2].kind == ActionKind::kStop);
  CHECK(b[2].target == ActionTarget::kEverything);

  // The unknown attribute is kept and reported where it was written.
  REQUIRE(config.warnings().size() == 1);
  CHECK(config.warnings()[0].location.line == 12);
  CHECK(config.warnings()[0].location.column == 56);
  CHECK(config.warnings()[0].message.find("priority") != std::string::npos);

  CHECK(config.FindCommand("sim") == &sim);
  CHECK(config.FindCommand("nope") == nullptr);
  CHECK(config.FindScript("other") == &config.scripts()[1]);
}

TEST_CASE("script actions print back as config text that parses the same") {
  const SheriffConfig config = ParseSheriffConfig(kConfig, "demo.pmd");
  for (const ScriptSpec& script : config.scripts()) {
    for (const ScriptAction& action : script.actions) {
      // Wrap each action in a config that defines what it refers to.
      const std::string text = std::string(kConfig) +
                               "script \"probe\" { " + action.ToString() + " }\n";
      const SheriffConfig again = ParseSheriffConfig(text, "again.pmd");
      const ScriptAction& parsed = again.FindScript("probe")->actions.at(0);
      CHECK(parsed.ToString() == action.ToString());
      CHECK(parsed.kind == action.kind);
      CHECK(parsed.target == action.target);
      CHECK(parsed.name == action.name);
      CHECK(parsed.wait == action.wait);
      CHECK(parsed.delay == action.delay);
    }
  }
  CHECK(config.scripts()[0].actions[2].ToString() ==
        "start cmd \"logger\" wait \"running\";");
}

TEST_CASE("strings support escapes and integers may be quoted") {
  const SheriffConfig config = ParseSheriffConfig(
      "cmd \"a\" { exec = \"echo \\\"hi\\\" \\\\ x\\ty\"; stop_signal = \"9\"; "
      "stop_time_allowed = \"2\"; }\n",
      "esc.pmd");
  CHECK(config.commands()[0].exec == "echo \"hi\" \\ x\ty");
  CHECK(config.commands()[0].stop_signal == 9);
  CHECK(config.commands()[0].stop_time_allowed == milliseconds(2000));
}

TEST_CASE("an empty config and a comment-only config are valid") {
  CHECK(ParseSheriffConfig("", "empty.pmd").commands().empty());
  CHECK(ParseSheriffConfig("# nothing\n  # here\n", "c.pmd").commands().empty());
}

TEST_CASE("parse errors say where and what was expected") {
  SECTION("missing ';' after a value") {
    const ConfigParseError e = ParseError(
        "cmd \"a\" {\n  exec = \"x\"\n  host = \"h\";\n}\n");
    CHECK(e.location().file == "bad.pmd");
    CHECK(e.location().line == 3);
    CHECK(e.location().column == 3);
    CHECK(e.message() ==
          "expected ';' after the value of 'exec', found identifier 'host'");
    const std::string what = e.what();
    CHECK(what.rfind("bad.pmd:3:3: error: expected ';'", 0) == 0);
    CHECK(what.find("\n    host = \"h\";\n    ^") != std::string::npos);
  }
  SECTION("unterminated string") {
    const ConfigParseError e = ParseError("cmd \"a\" { exec = \"oops;\n}\n");
    CHECK(e.location().line == 1);
    CHECK(e.location().column == 18);
    CHECK(e.message().find("unterminated string") != std::string::npos);
  }
  SECTION("unknown top-level keyword") {
    const ConfigParseError e = ParseError("\n\n  comand \"a\" {}\n");
    CHECK(e.location().line == 3);
    CHECK(e.location().column == 3);
    CHECK(e.message() ==
          "expected 'cmd', 'group' or 'script', found identifier 'comand'");
  }
  SECTION("invalid character") {
    const ConfigParseError e = ParseError("cmd \"a\" { exec = 'x'; }");
    CHECK(e.location().column == 18);
    CHECK(e.message().find("unexpected character '''") == 0);
  }
  SECTION("cmd without exec") {
    const ConfigParseError e = ParseError("cmd \"a\" { host = \"h\"; }");
    CHECK(e.location().column == 5);
    CHECK(e.message().find("has no 'exec'") != std::string::npos);
  }
  SECTION("duplicate command names") {
    const ConfigParseError e = ParseError(
        "cmd \"a\" { exec = \"x\"; }\ngroup \"g\" { cmd \"a\" { exec = \"y\"; } }");
    CHECK(e.location().line == 2);
    CHECK(e.location().column == 17);
    CHECK(e.message().find("first defined at bad.pmd:1:5") != std::string::npos);
  }
  SECTION("attribute values are checked") {
    CHECK(ParseError("cmd \"a\" { exec = \"x\"; auto_respawn = \"yes\"; }")
              .message()
              .find("\"true\" or \"false\"") != std::string::npos);
    CHECK(ParseError("cmd \"a\" { exec = \"x\"; stop_signal = 0; }")
              .message()
              .find("got 0") != std::string::npos);
    CHECK(ParseError("cmd \"a\" { exec = \"x\"; stop_time_allowed = \"soon\"; }")
              .message() == "expected an integer for 'stop_time_allowed', found "
                            "string \"soon\"");
    CHECK(ParseError("cmd \"a\" { exec = \"x\"; exec = \"y\"; }").message() ==
          "attribute 'exec' given twice in cmd \"a\"");
    CHECK(ParseError("group \"g\" { cmd \"a\" { exec = \"x\"; group = \"h\"; } }")
              .message()
              .find("inside group \"g\"") != std::string::npos);
  }
  SECTION("group names") {
    CHECK(ParseError("group \"a/b\" { }").message().find("'/' is not allowed") == 0);
    CHECK(ParseError("group \" \" { }").message() ==
          "expected a non-empty group name");
    CHECK(ParseError("group \"g\" { script \"s\" {} }").message() ==
          "expected 'cmd', 'group' or '}' in group \"g\", found identifier "
          "'script'");
  }
  SECTION("script syntax") {
    const ConfigParseError e = ParseError(
        "cmd \"a\" { exec = \"x\"; }\nscript \"s\" {\n  start cmd \"a\" wait \"up\";\n}");
    CHECK(e.location().line == 3);
    CHECK(e.location().column == 22);
    CHECK(e.message() == "expected \"running\" or \"stopped\", found string \"up\"");
    CHECK(ParseError("script \"s\" { start \"a\"; }").message() ==
          "expected 'cmd', 'group' or 'everything' after 'start', found string "
          "\"a\"");
    CHECK(ParseError("script \"s\" { wait ms x; }").message() ==
          "expected a number of milliseconds after 'wait ms', found identifier "
          "'x'");
    CHECK(ParseError("cmd \"a\" { exec = \"x\"; }\nscript \"s\" { wait cmd \"a\" "
                     "\"running\"; }")
              .message() ==
          "expected 'status' after the wait target, found string \"running\"");
    CHECK(ParseError("script \"s\" { launch cmd \"a\"; }").message().find(
              "expected a script action") == 0);
    CHECK(ParseError("script \"s\" { }\nscript \"s\" { }").message().find(
              "duplicate script name") == 0);
  }
  SECTION("unexpected end of file") {
    const ConfigParseError e = ParseError("group \"g\" {\n  cmd \"a\" { exec = \"x\"; }\n");
    CHECK(e.location().line == 3);
    CHECK(e.location().column == 1);
    CHECK(e.message() ==
          "expected 'cmd', 'group' or '}' in group \"g\", found end of file");
  }
}

TEST_CASE("scripts may only refer to what the config defines") {
  const ConfigParseError cmd = ParseError(
      "script \"s\" {\n  start cmd \"a\";\n  start cmd \"ghost\";\n}\n"
      "cmd \"a\" { exec = \"x\"; }");
  CHECK(cmd.location().line == 3);
  CHECK(cmd.location().column == 3);
  CHECK(cmd.message() == "script \"s\" refers to unknown cmd \"ghost\"");
  CHECK(ParseError("script \"s\" { wait group \"g\" status \"stopped\"; }").message() ==
        "script \"s\" refers to unknown group \"g\"");
  CHECK(ParseError("script \"s\" { run_script \"t\"; }").message() ==
        "script \"s\" runs unknown script \"t\"");
  const ConfigParseError cycle = ParseError(
      "script \"a\" { run_script \"b\"; }\nscript \"b\" { wait ms 1; run_script \"a\"; }");
  CHECK(cycle.location().line == 2);
  CHECK(cycle.location().column == 25);
  CHECK(cycle.message().find("\"a\" -> \"b\" -> \"a\"") != std::string::npos);
}

TEST_CASE("LoadSheriffConfig names a file it cannot read") {
  try {
    LoadSheriffConfig("/nonexistent/dir/x.pmd");
    FAIL("expected an exception");
  } catch (const std::runtime_error& e) {
    CHECK(std::string(e.what()).find("/nonexistent/dir/x.pmd") != std::string::npos);
  }
}

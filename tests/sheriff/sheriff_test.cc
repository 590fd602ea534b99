// The headless sheriff's run loop: --exit-when, --duration, signals, the end
// of a run, and the checks of its options.
#include <catch2/catch.hpp>

#include <signal.h>

#include "procs/sheriff/sheriff.h"
#include "procs/sheriff/sheriff_config_parser.h"
#include "tests/sheriff/test_util.h"

using namespace vimot::sheriff;
using namespace vimot::sheriff::test;

namespace {

// The demo shape: a simulator that runs to completion, plus services that
// would run forever.
constexpr char kDemo[] = R"(
  group "0.sim" {
    cmd "sim" { exec = "echo simulating; sleep 0.2; exit 3"; }
  }
  group "1.services" {
    cmd "logger" { exec = "sleep 30"; stop_signal = 15; }
    cmd "estimator" { exec = "sleep 30"; stop_signal = 15; }
  }
  script "demo" {
    start group "1.services" wait "running";
    start cmd "sim";
  }
)";

SheriffOptions Options(Recorder* rec) {
  SheriffOptions options;
  options.runner = rec->Options();
  options.runner.respawn_backoff_initial = milliseconds(20);
  return options;
}

}  // namespace

TEST_CASE("--exit-when: the command's exit stops the others and gives the exit code") {
  Recorder rec;
  SheriffOptions options = Options(&rec);
  options.exit_when = "sim";
  Sheriff sheriff(ParseSheriffConfig(kDemo, "demo.pmd"), options);
  const Clock::time_point start = Clock::now();
  const int code = sheriff.Run();
  INFO(rec.AllEvents());
  CHECK(code == 3);
  CHECK(Clock::now() - start < milliseconds(5000));
  CHECK(rec.HasOutput("[sim] simulating"));
  for (const char* name : {"logger", "estimator"}) {
    CHECK(sheriff.runner().state(name).status == CommandStatus::kStopped);
    CHECK(sheriff.runner().state(name).last_exit->signal == SIGTERM);
  }
  // Reverse start order: estimator was started after logger.
  CHECK(rec.EventIndex("stopping 'estimator'") < rec.EventIndex("stopping 'logger'"));
}

TEST_CASE("--exit-when with a script") {
  Recorder rec;
  SheriffOptions options = Options(&rec);
  options.script = "demo";
  options.exit_when = "sim";
  Sheriff sheriff(ParseSheriffConfig(kDemo, "demo.pmd"), options);
  CHECK(sheriff.Run() == 3);
  CHECK(sheriff.runner().state("logger").status == CommandStatus::kStopped);
}

TEST_CASE("--exit-when on an auto_respawn command: respawned on failure, done on exit 0") {
  TempDir dir;
  // Fails the first time (leaving a marker), succeeds the second time.
  const std::string config = R"(
    cmd "sim" {
      exec = "if [ -e \"$MARKER\" ]; then echo second; exit 0; fi; touch \"$MARKER\"; exit 1";
      auto_respawn = "true";
    }
    cmd "logger" { exec = "sleep 30"; stop_signal = 15; }
  )";
  Recorder rec;
  SheriffOptions options = Options(&rec);
  options.exit_when = "sim";
  options.runner.environment["MARKER"] = dir.path() + "/marker";
  Sheriff sheriff(ParseSheriffConfig(config, "respawn.pmd"), options);
  const int code = sheriff.Run();
  INFO(rec.AllEvents());
  CHECK(code == 0);
  CHECK(rec.HasOutput("[sim] second"));
  const CommandState& sim = sheriff.runner().state("sim");
  CHECK(sim.respawn_count == 1);
  CHECK(sim.status == CommandStatus::kStopped);  // The respawn after exit 0 was cancelled.
  CHECK(sheriff.runner().state("logger").status == CommandStatus::kStopped);
}

TEST_CASE("--duration stops everything and exits 0") {
  Recorder rec;
  SheriffOptions options = Options(&rec);
  options.group = "1.services";
  options.duration = milliseconds(300);
  Sheriff sheriff(ParseSheriffConfig(kDemo, "demo.pmd"), options);
  CHECK(sheriff.selected_commands() == std::vector<std::string>{"logger", "estimator"});
  const Clock::time_point start = Clock::now();
  CHECK(sheriff.Run() == 0);
  const auto took = Clock::now() - start;
  CHECK(took >= milliseconds(300));
  CHECK(took < milliseconds(5000));
  CHECK(sheriff.runner().state("sim").start_count == 0);  // Not in the group.
  CHECK(rec.EventIndex("duration reached") >= 0);
}

TEST_CASE("a signal stops everything in reverse order and gives 128 + signal") {
  Recorder rec;
  SheriffOptions options = Options(&rec);
  options.group = "1.services";
  Sheriff sheriff(ParseSheriffConfig(kDemo, "demo.pmd"), options);
  // One signal, once both services run.
  const int code = sheriff.Run([&]() {
    const bool up =
        sheriff.runner().state("estimator").status == CommandStatus::kRunning;
    return up && rec.EventIndex("received") < 0 ? SIGINT : 0;
  });
  INFO(rec.AllEvents());
  CHECK(code == 128 + SIGINT);
  CHECK(rec.EventIndex("stopping 'estimator'") < rec.EventIndex("stopping 'logger'"));
  CHECK(sheriff.runner().IsIdle());
}

TEST_CASE("a second signal kills what is still stopping") {
  const std::string config = R"(
    cmd "stubborn" { exec = "trap '' TERM; echo ready; sleep 30"; stop_signal = 15; stop_time_allowed = 30; }
  )";
  Recorder rec;
  Sheriff sheriff(ParseSheriffConfig(config, "stubborn.pmd"), Options(&rec));
  const Clock::time_point start = Clock::now();
  const int code = sheriff.Run([&]() {
    if (!rec.HasOutput("[stubborn] ready")) return 0;
    // First signal once it runs, a second one once it is stopping.
    if (rec.EventIndex("received") < 0) return SIGTERM;
    if (rec.EventIndex("stopping 'stubborn'") >= 0 && rec.EventIndex("killing") < 0) {
      return SIGINT;
    }
    return 0;
  });
  INFO(rec.AllEvents());
  CHECK(code == 128 + SIGTERM);
  CHECK(Clock::now() - start < milliseconds(10000));
  CHECK(sheriff.runner().state("stubborn").last_exit->signal == SIGKILL);
}

TEST_CASE("without --exit-when the run ends when nothing is left running") {
  Recorder rec;
  const std::string ok = R"(cmd "a" { exec = "exit 0"; } cmd "b" { exec = "echo b"; })";
  Sheriff good(ParseSheriffConfig(ok, "ok.pmd"), Options(&rec));
  CHECK(good.Run() == 0);
  const std::string bad = R"(cmd "a" { exec = "exit 0"; } cmd "b" { exec = "exit 5"; })";
  Sheriff failing(ParseSheriffConfig(bad, "bad.pmd"), Options(&rec));
  CHECK(failing.Run() == 1);
}

TEST_CASE("a failing script stops everything and gives 1") {
  const std::string config = R"(
    cmd "svc" { exec = "sleep 30"; stop_signal = 15; }
    cmd "oneshot" { exec = "true"; }
    script "s" {
      start cmd "svc";
      start cmd "oneshot";
      wait cmd "oneshot" status "stopped";
      wait cmd "oneshot" status "running";
    }
  )";
  Recorder rec;
  SheriffOptions options = Options(&rec);
  options.script = "s";
  Sheriff sheriff(ParseSheriffConfig(config, "s.pmd"), options);
  CHECK(sheriff.Run() == 1);
  CHECK(rec.EventIndex("will not run again") >= 0);
  CHECK(sheriff.runner().state("svc").status == CommandStatus::kStopped);
}

TEST_CASE("options that do not fit the config are rejected before anything starts") {
  const SheriffConfig config = ParseSheriffConfig(kDemo, "demo.pmd");
  Recorder rec;
  const auto error = [&](SheriffOptions options) -> std::string {
    try {
      Sheriff sheriff(config, options);
    } catch (const std::exception& e) {
      return e.what();
    }
    return "(accepted)";
  };
  SheriffOptions o = Options(&rec);
  o.script = "dmeo";
  CHECK(error(o) == "unknown script 'dmeo'; the config has: 'demo'");
  o = Options(&rec);
  o.group = "2.ui";
  CHECK(error(o).find("unknown group '2.ui'") == 0);
  o = Options(&rec);
  o.script = "demo";
  o.group = "0.sim";
  CHECK(error(o).find("not both") != std::string::npos);
  o = Options(&rec);
  o.exit_when = "simulator";
  CHECK(error(o) == "--exit-when: unknown command 'simulator'");
  o = Options(&rec);
  o.group = "1.services";
  o.exit_when = "sim";
  CHECK(error(o).find("'sim' is never started by group '1.services'") !=
        std::string::npos);
  o = Options(&rec);
  o.duration = milliseconds(0);
  CHECK(error(o).find("duration must be positive") == 0);

  ::unsetenv("VIMOT_SHERIFF_TEST_MISSING");
  const SheriffConfig env_config =
      ParseSheriffConfig(R"(cmd "x" { exec = "${VIMOT_SHERIFF_TEST_MISSING}/x"; })", "e.pmd");
  CHECK_THROWS_WITH(Sheriff(env_config, Options(&rec)),
                    Catch::Contains("undefined environment variable "
                                    "'VIMOT_SHERIFF_TEST_MISSING'") &&
                        Catch::Contains("cmd 'x' (e.pmd:1:5)"));
  CHECK(rec.events.empty());  // Nothing was started.
}

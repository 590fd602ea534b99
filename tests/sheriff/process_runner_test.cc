// ProcessRunner with real child processes. Every wait is on a condition with
// a generous timeout; the only long sleeps are in processes being stopped.
#include <catch2/catch.hpp>

#include <signal.h>

#include <cerrno>

#include "procs/sheriff/process_runner.h"
#include "tests/sheriff/test_util.h"

using namespace vimot::sheriff;
using namespace vimot::sheriff::test;

TEST_CASE("output is captured line by line with the command's name") {
  Recorder rec;
  ProcessRunner runner({Command("greeter", "echo hi; echo oops >&2; printf 'no newline'")},
                       rec.Options());
  runner.Start("greeter");
  CHECK(runner.state("greeter").status == CommandStatus::kRunning);
  CHECK(runner.state("greeter").pid > 0);
  REQUIRE(PollUntil(&runner, [&] { return runner.IsIdle(); }));

  CHECK(rec.HasOutput("[greeter] hi"));
  CHECK(rec.HasOutput("[greeter!] oops"));
  CHECK(rec.HasOutput("[greeter] no newline"));
  const CommandState& state = runner.state("greeter");
  CHECK(state.status == CommandStatus::kExited);
  REQUIRE(state.last_exit.has_value());
  CHECK(state.last_exit->exit_code == 0);
  CHECK(state.last_exit->signal == 0);
  CHECK(state.start_count == 1);
  CHECK(state.exit_count == 1);
  CHECK(state.pid == -1);
}

TEST_CASE("the exit code and a killing signal are reported") {
  Recorder rec;
  ProcessRunner runner({Command("three", "exit 3"), Command("killed", "kill -9 $$$$")},
                       rec.Options());
  runner.Start("three");
  runner.Start("killed");
  REQUIRE(PollUntil(&runner, [&] { return runner.IsIdle(); }));
  CHECK(runner.state("three").last_exit->exit_code == 3);
  CHECK(runner.state("three").last_exit->ShellStyleCode() == 3);
  CHECK(runner.state("killed").last_exit->signal == SIGKILL);
  CHECK(runner.state("killed").last_exit->ShellStyleCode() == 128 + SIGKILL);
  CHECK(rec.EventIndex("'three' exited with code 3") >= 0);
}

TEST_CASE("stop sends stop_signal to the process group and ends it in time") {
  Recorder rec;
  // A shell with a child shell, each trapping the signal: both traps
  // reporting proves the signal reached the whole process group. "ready" is
  // printed by the child once both traps are installed.
  CommandSpec spec = Command(
      "worker",
      "trap 'echo parent got TERM; wait; exit 3' TERM; "
      "sh -c 'trap \"echo child got TERM; exit 0\" TERM; echo ready; "
      "while true; do sleep 0.05; done' & wait");
  spec.stop_signal = SIGTERM;
  spec.stop_time_allowed = milliseconds(5000);
  ProcessRunner runner({spec}, rec.Options());
  runner.Start("worker");
  REQUIRE(PollUntil(&runner, [&] { return rec.HasOutput("[worker] ready"); }));

  const Clock::time_point stop_time = Clock::now();
  runner.Stop("worker");
  CHECK(runner.state("worker").status == CommandStatus::kStopping);
  REQUIRE(PollUntil(&runner, [&] {
    return runner.state("worker").status == CommandStatus::kStopped;
  }));
  CHECK(Clock::now() - stop_time < spec.stop_time_allowed);
  CHECK(rec.HasOutput("[worker] parent got TERM"));
  CHECK(rec.HasOutput("[worker] child got TERM"));
  CHECK(runner.state("worker").last_exit->exit_code == 3);
  CHECK(rec.EventIndex("with signal 15") >= 0);
  CHECK(rec.EventIndex("SIGKILL after 5.0 s") >= 0);
  CHECK(rec.EventIndex("sent SIGKILL") < 0);
  CHECK(runner.IsIdle());
}

TEST_CASE("a process that ignores the stop signal is SIGKILLed after stop_time_allowed") {
  Recorder rec;
  CommandSpec spec = Command("stubborn", "trap '' TERM; echo ready; sleep 30");
  spec.stop_signal = SIGTERM;
  spec.stop_time_allowed = milliseconds(300);
  ProcessRunner runner({spec}, rec.Options());
  runner.Start("stubborn");
  // Stopping before the trap is installed would just terminate the shell.
  REQUIRE(PollUntil(&runner, [&] { return rec.HasOutput("[stubborn] ready"); }));

  const Clock::time_point stop_time = Clock::now();
  runner.Stop("stubborn");
  REQUIRE(PollUntil(&runner, [&] {
    return runner.state("stubborn").status == CommandStatus::kStopped;
  }));
  const auto took = Clock::now() - stop_time;
  CHECK(took >= spec.stop_time_allowed);
  CHECK(took < milliseconds(5000));
  CHECK(runner.state("stubborn").last_exit->signal == SIGKILL);
  CHECK(rec.EventIndex("did not stop within 300 ms; sent SIGKILL") >= 0);
}

TEST_CASE("auto_respawn restarts an exiting command with a growing back-off") {
  Recorder rec;
  RunnerOptions options = rec.Options();
  options.respawn_backoff_initial = milliseconds(40);
  options.respawn_backoff_max = milliseconds(160);
  CommandSpec spec = Command("flaky", "echo run; exit 1");
  spec.auto_respawn = true;
  ProcessRunner runner({spec}, options);
  runner.Start("flaky");
  REQUIRE(PollUntil(&runner, [&] { return runner.state("flaky").respawn_count >= 4; }));

  const CommandState& state = runner.state("flaky");
  CHECK(state.start_count == state.respawn_count + 1);
  CHECK(rec.CountOutput("[flaky] run") >= 4);
  // Gaps between consecutive starts are at least 40, 80, 160, 160 ms. Only
  // lower bounds: a loaded machine may add any delay.
  std::vector<Clock::time_point> starts;
  for (const Recorder::Entry& e : rec.events) {
    if (e.text.find("started 'flaky'") == 0 || e.text.find("respawned 'flaky'") == 0) {
      starts.push_back(e.time);
    }
  }
  REQUIRE(starts.size() >= 5);
  const milliseconds expected[] = {milliseconds(40), milliseconds(80), milliseconds(160),
                                   milliseconds(160)};
  for (int i = 0; i < 4; ++i) {
    CHECK(starts[i + 1] - starts[i] >= expected[i]);
  }
  CHECK(rec.EventIndex("exited with code 1") >= 0);
  CHECK(rec.EventIndex("respawning in 40 ms (respawn #1)") >= 0);

  // Stop cancels the respawn for good.
  REQUIRE(PollUntil(&runner, [&] {
    return runner.state("flaky").status == CommandStatus::kRespawnPending;
  }));
  runner.Stop("flaky");
  CHECK(runner.state("flaky").status == CommandStatus::kStopped);
  const int respawns = runner.state("flaky").respawn_count;
  for (int i = 0; i < 10; ++i) runner.Poll(milliseconds(20));
  CHECK(runner.state("flaky").respawn_count == respawns);
  CHECK(runner.IsIdle());
}

TEST_CASE("restart stops, then starts again") {
  Recorder rec;
  ProcessRunner runner({Command("svc", "sleep 30")}, rec.Options());
  runner.Start("svc");
  const pid_t first = runner.state("svc").pid;
  runner.Restart("svc");
  REQUIRE(PollUntil(&runner, [&] { return runner.state("svc").start_count == 2; }));
  CHECK(runner.state("svc").status == CommandStatus::kRunning);
  CHECK(runner.state("svc").pid != first);
  CHECK(runner.state("svc").last_exit->signal == SIGTERM);
}

TEST_CASE("StopAll stops in reverse start order, one after the other") {
  Recorder rec;
  ProcessRunner runner({Command("a", "sleep 30"), Command("b", "sleep 30"),
                        Command("c", "sleep 30")},
                       rec.Options());
  runner.Start("b");
  runner.Start("a");
  runner.Start("c");
  runner.StopAll();
  REQUIRE(PollUntil(&runner, [&] { return runner.IsIdle(); }));
  const int c = rec.EventIndex("stopping 'c'");
  const int a = rec.EventIndex("stopping 'a'");
  const int b = rec.EventIndex("stopping 'b'");
  REQUIRE(c >= 0);
  CHECK(a > rec.EventIndex("'c' stopped"));
  CHECK(b > rec.EventIndex("'a' stopped"));
  CHECK(c < a);
  for (const char* name : {"a", "b", "c"}) {
    CHECK(runner.state(name).status == CommandStatus::kStopped);
  }
}

TEST_CASE("environment options reach exec expansion and the child") {
  Recorder rec;
  RunnerOptions options = rec.Options();
  options.environment["VIMOT_SHERIFF_TEST_DIR"] = "/from/options";
  ProcessRunner runner(
      {Command("env", "echo expanded=$VIMOT_SHERIFF_TEST_DIR; printenv VIMOT_SHERIFF_TEST_DIR")},
      options);
  runner.Start("env");
  REQUIRE(PollUntil(&runner, [&] { return runner.IsIdle(); }));
  CHECK(rec.HasOutput("[env] expanded=/from/options"));
  CHECK(rec.HasOutput("[env] /from/options"));
}

TEST_CASE("an undefined variable fails the start and names the variable") {
  Recorder rec;
  ::unsetenv("VIMOT_SHERIFF_TEST_NOPE");
  ProcessRunner runner({Command("bad", "${VIMOT_SHERIFF_TEST_NOPE}/x")}, rec.Options());
  CHECK_THROWS_WITH(runner.ExpandedExec("bad"),
                    Catch::Contains("'VIMOT_SHERIFF_TEST_NOPE'") && Catch::Contains("cmd 'bad'"));
  runner.Start("bad");
  CHECK(runner.state("bad").status == CommandStatus::kFailed);
  CHECK(runner.state("bad").failure.find("VIMOT_SHERIFF_TEST_NOPE") != std::string::npos);
  CHECK(rec.EventIndex("cannot start 'bad'") >= 0);
  CHECK(runner.IsIdle());
}

TEST_CASE("commands of other hosts are reported and never started") {
  Recorder rec;
  CommandSpec remote = Command("far", "echo should not run");
  remote.host = "some-other-robot";
  CommandSpec here = Command("near", "true");
  here.host = "localhost";
  ProcessRunner runner({remote, here}, rec.Options());
  CHECK_FALSE(runner.IsLocal("far"));
  CHECK(runner.IsLocal("near"));
  runner.Start("far");
  CHECK(runner.state("far").status == CommandStatus::kRemote);
  CHECK(runner.state("far").start_count == 0);
  CHECK(rec.EventIndex("host 'some-other-robot' is not this machine") >= 0);
  CHECK(runner.IsIdle());
}

TEST_CASE("bad input is rejected with the offending value") {
  CHECK_THROWS_WITH(ProcessRunner({Command("a", "x"), Command("a", "y")}),
                    Catch::Contains("duplicate command name 'a'"));
  RunnerOptions zero;
  zero.respawn_backoff_initial = milliseconds(0);
  CHECK_THROWS_AS(ProcessRunner({}, zero), std::invalid_argument);
  ProcessRunner runner({Command("a", "true")});
  CHECK_THROWS_WITH(runner.Start("b"), Catch::Contains("unknown command 'b'"));
  CHECK_THROWS_AS(runner.state("b"), std::invalid_argument);
}

TEST_CASE("destroying the runner kills and reaps what still runs") {
  pid_t pid = -1;
  {
    Recorder rec;
    ProcessRunner runner({Command("sleeper", "sleep 30")}, rec.Options());
    runner.Start("sleeper");
    pid = runner.state("sleeper").pid;
    REQUIRE(pid > 0);
  }
  // Reaped: the pid no longer names a process (not even a zombie).
  CHECK(::kill(pid, 0) == -1);
  CHECK(errno == ESRCH);
}

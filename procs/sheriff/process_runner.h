#pragma once
// Runs procman commands as local child processes. No LCM: the runner is the
// "deputy" half of procman for this machine, driven by direct calls. A later
// LCM front end can map procman orders onto Start/Stop/Restart and publish
// state() as deputy info without touching this class.

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "procs/sheriff/command_control.h"
#include "procs/sheriff/group_watchdog.h"
#include "procs/sheriff/line_splitter.h"
#include "procs/sheriff/sheriff_config.h"
#include "procs/sheriff/unique_fd.h"

namespace vimot::sheriff {

enum class CommandStatus {
  /// Never started, or stopped on request.
  kStopped,
  /// The main process is alive.
  kRunning,
  /// Stop signal sent; waiting for the process group to end.
  kStopping,
  /// Exited on its own; auto_respawn will start it again after a back-off.
  kRespawnPending,
  /// Exited on its own and will not be restarted.
  kExited,
  /// Could not be started (undefined variable, fork failure); see `failure`.
  kFailed,
  /// Belongs to another host; never started here.
  kRemote,
};

/// "stopped", "running", "stopping", "respawn pending", "exited", "failed",
/// "remote".
const char* ToString(CommandStatus status);

/// How a process ended.
struct ExitInfo {
  /// exit() status when `signal` is 0.
  int exit_code{0};
  /// Terminating signal, 0 if the process exited normally.
  int signal{0};

  /// The shell's convention: the exit status, or 128 + signal.
  int ShellStyleCode() const { return signal != 0 ? 128 + signal : exit_code; }
  /// "code 3" or "signal 15 (Terminated)".
  std::string ToString() const;
};

/// What the runner knows about one command.
struct CommandState {
  CommandStatus status{CommandStatus::kStopped};
  /// Pid (= process group id) of the current process, -1 when none.
  pid_t pid{-1};
  /// How the last process ended, if one has.
  std::optional<ExitInfo> last_exit;
  /// Processes started, including respawns.
  int start_count{0};
  /// Starts done by auto_respawn.
  int respawn_count{0};
  /// Processes that ended (on their own or stopped).
  int exit_count{0};
  /// Why the command is kFailed.
  std::string failure;
};

enum class OutputStream { kStdout, kStderr };

struct RunnerOptions {
  /// Delay before the first respawn of a command that exited; doubles after
  /// every further exit up to respawn_backoff_max, so a command that crashes
  /// at start-up does not spin the machine.
  std::chrono::milliseconds respawn_backoff_initial{1000};
  std::chrono::milliseconds respawn_backoff_max{30000};
  /// A process that ran at least this long before exiting is considered to
  /// have been healthy: its back-off starts again from the initial value.
  std::chrono::milliseconds respawn_backoff_reset_after{30000};
  /// Set in the children's environment (overriding inherited values) and
  /// used for ${VAR} expansion in exec before the process environment.
  std::map<std::string, std::string> environment;
  /// Names this machine answers to besides "localhost", "127.0.0.1" and the
  /// empty string; defaults to gethostname() (full and short) when empty.
  std::vector<std::string> local_host_names;
  /// Make this process a child subreaper (Linux prctl) so that processes a
  /// command's shell leaves behind are re-parented here rather than to init,
  /// and reaped here: in containers init often never reaps, and a zombie
  /// keeps its process group alive, which would make every stop wait for
  /// the SIGKILL deadline.
  bool adopt_orphans{true};
  /// One line of a child's output, without '\n'. Default: `[name] line` on
  /// the sheriff's stdout or stderr, matching the child's stream.
  std::function<void(const std::string& name, OutputStream stream,
                     const std::string& line)>
      on_output;
  /// One line about what the runner did (started, exited, stopping, ...).
  /// Default: `[sheriff] message` on stderr.
  std::function<void(const std::string& message)> on_event;
};

/// How a process ended, from a waitpid() status.
ExitInfo DecodeWaitStatus(int wait_status);
/// The waitpid() status of an ExitInfo (procman reports it in deputy info).
int EncodeWaitStatus(const ExitInfo& exit);

/// The line given to `/bin/sh -c` for `command`: "exec <command>" when it is
/// one simple command (no ; & | ( ) or newline outside quotes, other than
/// the & of a redirection such as 2>&1; not starting
/// with an assignment, a reserved word or a shell builtin), so the program
/// replaces the shell: the pid, exit status and parent-death signal are then
/// the program's own. Anything else is left to the shell as written.
std::string ShellCommandLine(const std::string& command);

/// Starts, watches, respawns and stops the commands of a config.
///
/// Each command runs as `/bin/sh -c "<exec>"` (see ShellCommandLine) in its
/// own process group, so
/// the stop signal reaches everything the shell started, and so a Ctrl-C in
/// the sheriff's terminal reaches only the sheriff, which then stops the
/// commands in order. stdout and stderr are read through non-blocking pipes
/// and forwarded line by line.
///
/// Single-threaded and event-loop driven: the caller calls Poll() repeatedly;
/// every state change happens inside Poll() or the command methods. A respawn
/// is never started in the same Poll() call that saw the exit, so a caller
/// that inspects state() after each Poll() can still cancel it with Stop().
///
/// A command's process group is never lost: when its main process ends on
/// its own (or is killed) while other members of the group still run, they
/// are stopped like a command (stop_signal, SIGKILL after stop_time_allowed)
/// before the command counts as exited or is respawned. The commands die
/// with the runner's process, even by SIGKILL: each child gets
/// PR_SET_PDEATHSIG (its stop_signal) and a GroupWatchdog stops every group.
class ProcessRunner : public CommandControl {
 public:
  /// Throws std::invalid_argument on duplicate or empty command names and on
  /// non-positive back-off options.
  explicit ProcessRunner(std::vector<CommandSpec> commands,
                         RunnerOptions options = {});
  /// SIGKILLs and reaps whatever is still running: a runner that goes away
  /// must not leave orphans behind.
  ~ProcessRunner() override;

  ProcessRunner(const ProcessRunner&) = delete;
  ProcessRunner& operator=(const ProcessRunner&) = delete;

  /// Starts the command unless it is running. Expands ${VAR} in exec first;
  /// on an undefined variable (or a fork failure) the command becomes
  /// kFailed and an event names the cause. A stopping command is started
  /// again as soon as it has stopped. Remote commands are reported and
  /// skipped. Throws std::invalid_argument for an unknown name.
  void Start(const std::string& name) override;
  /// Sends stop_signal to the command's process group, then SIGKILL after
  /// stop_time_allowed. Cancels a pending respawn or restart. No-op for a
  /// command that is not running.
  void Stop(const std::string& name) override;
  /// Stop, then Start once the process group has ended.
  void Restart(const std::string& name) override;
  /// Stops every command one after the other in reverse start order (the
  /// last started is stopped first, as the ones started earlier are usually
  /// what later ones depend on), waiting for each to end before the next.
  /// Pending respawns are cancelled at once.
  void StopAll();
  /// SIGKILLs every process group now (second Ctrl-C).
  void KillAll();

  /// Waits up to `max_wait` for output or a timer, then forwards output,
  /// reaps exited processes, sends SIGKILLs that are due and starts due
  /// respawns. Returns early when something happened.
  void Poll(std::chrono::milliseconds max_wait);

  /// The command line Start() would run: exec with ${VAR} expanded from
  /// RunnerOptions::environment, then the process environment. Throws
  /// std::runtime_error naming an undefined variable and the command, so a
  /// caller can reject a config before starting anything.
  std::string ExpandedExec(const std::string& name) const;

  /// True when nothing is alive, no respawn is pending and StopAll() is done.
  bool IsIdle() const;

  bool HasCommand(const std::string& name) const;
  /// Throws std::invalid_argument for an unknown name.
  const CommandState& state(const std::string& name) const override;
  const CommandSpec& spec(const std::string& name) const;
  /// False for commands of another host.
  bool IsLocal(const std::string& name) const override;
  /// In the order given to the constructor.
  std::vector<std::string> command_names() const;

 private:
  using Clock = std::chrono::steady_clock;

  struct OutputPipe {
    UniqueFd fd;
    LineSplitter lines;
    OutputStream stream{OutputStream::kStdout};
  };

  struct Record {
    CommandSpec spec;
    bool local{true};
    CommandState state;
    /// Process group of the latest run (= its first pid), 0 before the first
    /// run; kept after the main process ends so that group members it left
    /// behind are still reaped.
    pid_t pgid{0};
    /// Start sequence number, for reverse-order shutdown.
    std::size_t start_sequence{0};
    Clock::time_point started_at{};
    /// True once the main process has been reaped while stopping; the
    /// command stays kStopping until its process group is gone.
    bool leader_reaped{false};
    bool kill_sent{false};
    Clock::time_point kill_at{};
    Clock::time_point respawn_at{};
    std::chrono::milliseconds backoff{0};
    bool restart_pending{false};
    /// The main process ended on its own and the rest of its group is being
    /// stopped (kStopping); then it counts as exited or is respawned.
    bool ending_on_its_own{false};
    Clock::time_point leader_exit_at{};
    /// Pipes of the latest run; kept open after the process ends until EOF,
    /// so output written just before exit is not lost.
    std::vector<OutputPipe> pipes;
  };

  /// Throws std::invalid_argument for an unknown name.
  std::size_t IndexOf(const std::string& name) const;
  Record& Find(const std::string& name);
  const Record& Find(const std::string& name) const;
  void StartRecord(Record* r, bool is_respawn);
  void StopRecord(Record* r);
  void ReapGroup(Record* r, Clock::time_point now);
  void OnLeaderExit(Record* r, int wait_status, Clock::time_point now);
  void FinishStop(Record* r);
  /// Exited (or respawn pending) after the main process ended on its own.
  void FinishExit(Record* r);
  /// The group has ended: forget its id here and in the watchdog.
  void ForgetGroup(Record* r);
  void ReadPipe(Record* r, OutputPipe* pipe);
  void FlushPipes(Record* r);
  void AdvanceStopAll();
  void Emit(const std::string& message) const;
  bool IsLocalHost(const std::string& host) const;
  static bool IsAlive(const Record& r);

  RunnerOptions options_;
  std::vector<Record> records_;
  std::map<std::string, std::size_t> index_;
  std::size_t next_start_sequence_{1};
  /// Indices still to be stopped by StopAll(), next first.
  std::vector<std::size_t> stop_queue_;
  /// Created with the first command started.
  std::optional<GroupWatchdog> watchdog_;
};

}  // namespace vimot::sheriff

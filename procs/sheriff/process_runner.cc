#include "procs/sheriff/process_runner.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>

#include "procs/sheriff/env_expansion.h"

extern char** environ;

namespace vimot::sheriff {

namespace {

using std::chrono::milliseconds;

// Without SIGCHLD handling (a library must not own the process's signal
// handlers), exits are noticed by polling waitpid() at least this often.
constexpr milliseconds kMaxPollInterval{50};
// Bytes read from one pipe per Poll(), so one chatty child cannot starve the
// others or the timers.
constexpr std::size_t kMaxReadPerPoll = 64 * 1024;

std::string SignalName(int signal) {
  const char* text = ::strsignal(signal);
  return "signal " + std::to_string(signal) + " (" +
         (text != nullptr ? text : "unknown") + ")";
}

std::string Seconds(milliseconds d) {
  if (d < milliseconds(1000)) return std::to_string(d.count()) + " ms";
  char text[32];
  std::snprintf(text, sizeof(text), "%.1f s", static_cast<double>(d.count()) / 1000.0);
  return text;
}

// True while any process (zombies included) is in process group `pgid`.
bool GroupExists(pid_t pgid) {
  return pgid > 0 && (::kill(-pgid, 0) == 0 || errno != ESRCH);
}

std::vector<std::string> DefaultLocalHostNames() {
  std::vector<std::string> names;
  char host[HOST_NAME_MAX + 1] = {};
  if (::gethostname(host, sizeof(host) - 1) == 0 && host[0] != '\0') {
    const std::string full(host);
    names.push_back(full);
    const std::size_t dot = full.find('.');
    if (dot != std::string::npos) names.push_back(full.substr(0, dot));
  }
  return names;
}

// Words the shell must see first: reserved words and builtins that exist as
// no program, so "exec <word> ..." would fail or mean something else.
bool IsShellWord(const std::string& word) {
  static const char* const kWords[] = {
      "if", "then", "else", "elif", "fi", "for", "while", "until", "do", "done", "case", "esac", "{", "}",
      "!", "[[", "exec", "cd", "export", "set", "unset", "eval", "trap", ".", "source", "readonly", "shift",
      "wait", "alias", "unalias", "umask", "ulimit", "read", "local", "return", "exit", "break", "continue",
      "times", "type", "command", "hash", "getopts", "jobs", "fg", "bg", "function", "time"};
  for (const char* w : kWords) {
    if (word == w) return true;
  }
  return false;
}

bool IsSimpleCommand(const std::string& command) {
  char quote = 0;
  std::string first_word;
  bool in_first_word = false, first_word_done = false;
  for (std::size_t i = 0; i < command.size(); ++i) {
    const char c = command[i];
    if (quote == '\'') {
      if (c == '\'') quote = 0;
    } else if (c == '\\') {
      ++i;  // the escaped character is literal
    } else if (quote == '"') {
      if (c == '"') quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '&' && i > 0 && (command[i - 1] == '>' || command[i - 1] == '<')) {
      // A redirection (2>&1, <&3), not a control operator. (`&>file` is
      // bash; /bin/sh reads it as `&` then `>file`.)
    } else if (std::strchr(";&|()\n", c) != nullptr) {
      return false;  // a list, pipeline, background job or subshell
    }
    // The first word, as written (quotes make it a program name anyway).
    const bool space = quote == 0 && (c == ' ' || c == '\t');
    if (!first_word_done) {
      if (!space) {
        in_first_word = true;
        first_word.push_back(c);
        if (quote == 0 && c == '=') return false;  // VAR=value prefix
      } else if (in_first_word) {
        first_word_done = true;
      }
    }
  }
  return quote == 0 && !first_word.empty() && !IsShellWord(first_word);
}

}  // namespace

std::string ShellCommandLine(const std::string& command) {
  return IsSimpleCommand(command) ? "exec " + command : command;
}

const char* ToString(CommandStatus status) {
  switch (status) {
    case CommandStatus::kStopped:
      return "stopped";
    case CommandStatus::kRunning:
      return "running";
    case CommandStatus::kStopping:
      return "stopping";
    case CommandStatus::kRespawnPending:
      return "respawn pending";
    case CommandStatus::kExited:
      return "exited";
    case CommandStatus::kFailed:
      return "failed";
    case CommandStatus::kRemote:
      return "remote";
  }
  return "unknown";
}

ExitInfo DecodeWaitStatus(int wait_status) {
  ExitInfo info;
  if (WIFSIGNALED(wait_status)) {
    info.signal = WTERMSIG(wait_status);
  } else if (WIFEXITED(wait_status)) {
    info.exit_code = WEXITSTATUS(wait_status);
  }
  return info;
}

int EncodeWaitStatus(const ExitInfo& exit) {
  return exit.signal != 0 ? exit.signal : (exit.exit_code & 0xff) << 8;
}

std::string ExitInfo::ToString() const {
  return signal != 0 ? SignalName(signal) : "code " + std::to_string(exit_code);
}

ProcessRunner::ProcessRunner(std::vector<CommandSpec> commands,
                             RunnerOptions options)
    : options_(std::move(options)) {
  if (options_.respawn_backoff_initial <= milliseconds(0) ||
      options_.respawn_backoff_max < options_.respawn_backoff_initial) {
    throw std::invalid_argument(
        "ProcessRunner: need 0 < respawn_backoff_initial <= "
        "respawn_backoff_max, got " +
        std::to_string(options_.respawn_backoff_initial.count()) + " ms and " +
        std::to_string(options_.respawn_backoff_max.count()) + " ms");
  }
  if (options_.local_host_names.empty()) {
    options_.local_host_names = DefaultLocalHostNames();
  }
  if (!options_.on_output) {
    options_.on_output = [](const std::string& name, OutputStream stream,
                            const std::string& line) {
      std::ostream& out = stream == OutputStream::kStdout ? std::cout : std::cerr;
      // Flushed per line: the sheriff's output is usually watched live or
      // piped into a log, and lines from different children must not wait
      // in a buffer behind each other.
      out << "[" << name << "] " << line << std::endl;
    };
  }
  if (!options_.on_event) {
    options_.on_event = [](const std::string& message) {
      std::cerr << "[sheriff] " << message << std::endl;
    };
  }
  if (options_.adopt_orphans) {
    // Best effort: without it stops still work, only slower when init does
    // not reap (see RunnerOptions::adopt_orphans).
    ::prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0);
  }
  records_.reserve(commands.size());
  for (CommandSpec& spec : commands) {
    if (spec.name.empty()) {
      throw std::invalid_argument("ProcessRunner: a command has no name");
    }
    if (!index_.emplace(spec.name, records_.size()).second) {
      throw std::invalid_argument("ProcessRunner: duplicate command name '" +
                                  spec.name + "'");
    }
    Record record;
    record.spec = std::move(spec);
    record.local = IsLocalHost(record.spec.host);
    if (!record.local) record.state.status = CommandStatus::kRemote;
    records_.push_back(std::move(record));
  }
}

ProcessRunner::~ProcessRunner() {
  for (Record& r : records_) {
    if (r.pgid > 0) ::kill(-r.pgid, SIGKILL);
    if (IsAlive(r) && !r.leader_reaped && r.state.pid > 0) {
      // The main process may have left its group (setsid); kill it directly
      // too, then wait: SIGKILL cannot be ignored, so this returns promptly.
      ::kill(r.state.pid, SIGKILL);
      int status = 0;
      while (::waitpid(r.state.pid, &status, 0) < 0 && errno == EINTR) {
      }
    }
    if (r.pgid > 0) {
      // Members the dead shell left behind are ours now (adopt_orphans) and
      // were SIGKILLed with the group: wait for them, so no zombie outlives
      // the runner. ECHILD ends the loop once none is left.
      int status = 0;
      while (::waitpid(-r.pgid, &status, 0) > 0 || errno == EINTR) {
      }
    }
  }
}

bool ProcessRunner::IsLocalHost(const std::string& host) const {
  if (host.empty() || host == "localhost" || host == "127.0.0.1") return true;
  for (const std::string& name : options_.local_host_names) {
    if (host == name) return true;
  }
  return false;
}

bool ProcessRunner::IsAlive(const Record& r) {
  return r.state.status == CommandStatus::kRunning ||
         r.state.status == CommandStatus::kStopping;
}

std::size_t ProcessRunner::IndexOf(const std::string& name) const {
  const auto it = index_.find(name);
  if (it == index_.end()) {
    throw std::invalid_argument("ProcessRunner: unknown command '" + name + "'");
  }
  return it->second;
}

ProcessRunner::Record& ProcessRunner::Find(const std::string& name) {
  return records_[IndexOf(name)];
}

const ProcessRunner::Record& ProcessRunner::Find(const std::string& name) const {
  return records_[IndexOf(name)];
}

bool ProcessRunner::HasCommand(const std::string& name) const {
  return index_.count(name) > 0;
}

const CommandState& ProcessRunner::state(const std::string& name) const {
  return Find(name).state;
}

const CommandSpec& ProcessRunner::spec(const std::string& name) const {
  return Find(name).spec;
}

bool ProcessRunner::IsLocal(const std::string& name) const {
  return Find(name).local;
}

std::vector<std::string> ProcessRunner::command_names() const {
  std::vector<std::string> names;
  for (const Record& r : records_) names.push_back(r.spec.name);
  return names;
}

void ProcessRunner::Emit(const std::string& message) const {
  options_.on_event(message);
}

std::string ProcessRunner::ExpandedExec(const std::string& name) const {
  const Record& r = Find(name);
  try {
    return ExpandEnvironmentVariables(
        r.spec.exec, [this](const std::string& var) -> std::optional<std::string> {
          const auto it = options_.environment.find(var);
          if (it != options_.environment.end()) return it->second;
          return LookupProcessEnvironment(var);
        });
  } catch (const std::runtime_error& e) {
    const std::string where = r.spec.location.file.empty()
                                  ? ""
                                  : " (" + r.spec.location.ToString() + ")";
    throw std::runtime_error("cmd '" + name + "'" + where + ": " + e.what());
  }
}

void ProcessRunner::Start(const std::string& name) {
  Record& r = Find(name);
  switch (r.state.status) {
    case CommandStatus::kRunning:
      return;
    case CommandStatus::kStopping:
      r.restart_pending = true;
      return;
    default:
      StartRecord(&r, false);
  }
}

void ProcessRunner::Stop(const std::string& name) { StopRecord(&Find(name)); }

void ProcessRunner::Restart(const std::string& name) {
  Record& r = Find(name);
  if (!IsAlive(r)) {
    StartRecord(&r, false);
    return;
  }
  StopRecord(&r);
  r.restart_pending = true;
}

void ProcessRunner::StartRecord(Record* r, bool is_respawn) {
  const std::string& name = r->spec.name;
  if (!r->local) {
    Emit("not starting '" + name + "': host '" + r->spec.host +
         "' is not this machine, and remote deputies are not supported");
    return;
  }
  const auto fail = [&](const std::string& why) {
    r->state.status = CommandStatus::kFailed;
    r->state.failure = why;
    Emit("cannot start '" + name + "': " + why);
  };
  std::string command;
  try {
    command = ExpandedExec(name);
  } catch (const std::exception& e) {
    fail(e.what());
    return;
  }

  // Output still buffered from the previous run belongs before the new run's.
  FlushPipes(r);

  if (!watchdog_) {
    try {
      watchdog_.emplace();
    } catch (const std::exception& e) {
      Emit(std::string("no watchdog (commands would outlive a killed sheriff): ") + e.what());
    }
  }

  int out_fds[2] = {-1, -1};
  int err_fds[2] = {-1, -1};
  // O_CLOEXEC: no child may inherit another child's pipe ends, or EOF would
  // never arrive while any other command runs.
  if (::pipe2(out_fds, O_CLOEXEC) != 0) {
    fail(std::string("pipe: ") + std::strerror(errno));
    return;
  }
  UniqueFd out_read(out_fds[0]), out_write(out_fds[1]);
  if (::pipe2(err_fds, O_CLOEXEC) != 0) {
    fail(std::string("pipe: ") + std::strerror(errno));
    return;
  }
  UniqueFd err_read(err_fds[0]), err_write(err_fds[1]);

  // Everything the child needs is built before fork(): between fork() and
  // exec() only async-signal-safe calls are allowed.
  std::vector<std::string> env_strings;
  for (char** e = environ; e != nullptr && *e != nullptr; ++e) {
    const std::string entry(*e);
    const std::string key = entry.substr(0, entry.find('='));
    if (options_.environment.count(key) == 0) env_strings.push_back(entry);
  }
  for (const auto& [key, value] : options_.environment) {
    env_strings.push_back(key + "=" + value);
  }
  std::vector<char*> envp;
  for (std::string& s : env_strings) envp.push_back(s.data());
  envp.push_back(nullptr);
  std::string sh = "/bin/sh", dash_c = "-c", line = ShellCommandLine(command);
  std::vector<char*> argv = {sh.data(), dash_c.data(), line.data(), nullptr};
  const pid_t sheriff_pid = ::getpid();
  const int death_signal = r->spec.stop_signal;
  const char exec_failed[] = "vimot-sheriff: cannot exec /bin/sh\n";

  // All signals stay blocked across fork() until the child has reset their
  // dispositions: a stop signal that reached the child before that would
  // otherwise run one of the parent's handlers inside the half-made child.
  sigset_t all_signals, parent_mask;
  ::sigfillset(&all_signals);
  ::pthread_sigmask(SIG_SETMASK, &all_signals, &parent_mask);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    // Die with the sheriff (the program itself when the shell exec's it);
    // the watchdog covers the rest of the group. If the sheriff died before
    // the prctl, the parent is already someone else.
    ::prctl(PR_SET_PDEATHSIG, death_signal);
    if (::getppid() != sheriff_pid) ::_exit(127);
    // Handlers would be reset by exec, but "ignore" would survive it: start
    // the command with default dispositions whatever the sheriff ignores
    // (SIGPIPE) or handles.
    struct sigaction dfl {};
    dfl.sa_handler = SIG_DFL;
    for (int s = 1; s < NSIG; ++s) ::sigaction(s, &dfl, nullptr);
    sigset_t none;
    ::sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    // O_CLOEXEC: only the dup2() copy on stdin survives the exec.
    const int null_fd = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (null_fd >= 0) ::dup2(null_fd, STDIN_FILENO);
    ::dup2(out_fds[1], STDOUT_FILENO);
    ::dup2(err_fds[1], STDERR_FILENO);
    ::execve(argv[0], argv.data(), envp.data());
    const ssize_t ignored = ::write(STDERR_FILENO, exec_failed, sizeof(exec_failed) - 1);
    (void)ignored;
    ::_exit(127);
  }
  const int fork_errno = errno;
  ::pthread_sigmask(SIG_SETMASK, &parent_mask, nullptr);
  if (pid < 0) {
    fail(std::string("fork: ") + std::strerror(fork_errno));
    return;
  }
  // Also set in the parent so the group exists before we might signal it;
  // fails harmlessly (EACCES) if the child has already exec'ed.
  ::setpgid(pid, pid);

  out_write.reset();
  err_write.reset();
  // Only our read ends are non-blocking; a child writing to a full pipe
  // must block as with a terminal, not get EAGAIN.
  ::fcntl(out_read.get(), F_SETFL, ::fcntl(out_read.get(), F_GETFL) | O_NONBLOCK);
  ::fcntl(err_read.get(), F_SETFL, ::fcntl(err_read.get(), F_GETFL) | O_NONBLOCK);
  r->pipes.clear();
  r->pipes.push_back({std::move(out_read), LineSplitter(), OutputStream::kStdout});
  r->pipes.push_back({std::move(err_read), LineSplitter(), OutputStream::kStderr});

  r->state.status = CommandStatus::kRunning;
  r->state.pid = pid;
  r->state.failure.clear();
  ++r->state.start_count;
  if (is_respawn) ++r->state.respawn_count;
  // The kernel never hands out a pid that is still a process group id, so
  // another record holding this id as its old group has seen it end.
  for (Record& other : records_) {
    if (other.pgid == pid) other.pgid = 0;
  }
  r->pgid = pid;
  if (watchdog_) watchdog_->Watch(pid, r->spec.stop_signal, r->spec.stop_time_allowed);
  r->start_sequence = next_start_sequence_++;
  r->started_at = Clock::now();
  r->leader_reaped = false;
  r->kill_sent = false;
  r->restart_pending = false;
  r->ending_on_its_own = false;
  Emit((is_respawn ? "respawned '" : "started '") + name + "' (pid " +
       std::to_string(pid) + "): " + command);
}

void ProcessRunner::StopRecord(Record* r) {
  r->restart_pending = false;
  if (r->state.status == CommandStatus::kRespawnPending) {
    r->state.status = CommandStatus::kStopped;
    Emit("cancelled the respawn of '" + r->spec.name + "'");
    return;
  }
  if (r->state.status == CommandStatus::kStopping && r->ending_on_its_own) {
    // Already being stopped; now it ends as stopped, not as exited.
    r->ending_on_its_own = false;
    return;
  }
  if (r->state.status != CommandStatus::kRunning) return;
  // ESRCH here only means the process ended and has not been reaped yet;
  // the next Poll() reaps it and completes the stop.
  ::kill(-r->pgid, r->spec.stop_signal);
  r->state.status = CommandStatus::kStopping;
  r->kill_sent = false;
  r->kill_at = Clock::now() + r->spec.stop_time_allowed;
  Emit("stopping '" + r->spec.name + "' (pid " + std::to_string(r->pgid) +
       ") with " + SignalName(r->spec.stop_signal) + "; SIGKILL after " +
       Seconds(r->spec.stop_time_allowed));
}

void ProcessRunner::StopAll() {
  std::vector<std::size_t> alive;
  for (std::size_t i = 0; i < records_.size(); ++i) {
    Record& r = records_[i];
    r.restart_pending = false;
    r.ending_on_its_own = false;  // stopped now, never respawned
    if (r.state.status == CommandStatus::kRespawnPending) StopRecord(&r);
    if (IsAlive(r)) alive.push_back(i);
  }
  std::sort(alive.begin(), alive.end(), [this](std::size_t a, std::size_t b) {
    return records_[a].start_sequence > records_[b].start_sequence;
  });
  stop_queue_ = std::move(alive);
  AdvanceStopAll();
}

void ProcessRunner::KillAll() {
  for (Record& r : records_) {
    r.restart_pending = false;
    r.ending_on_its_own = false;
    if (r.state.status == CommandStatus::kRespawnPending) StopRecord(&r);
    if (!IsAlive(r)) continue;
    ::kill(-r.pgid, SIGKILL);
    r.state.status = CommandStatus::kStopping;
    r.kill_sent = true;
    Emit("killing '" + r.spec.name + "' (pid " + std::to_string(r.pgid) +
         ") with SIGKILL");
  }
  stop_queue_.clear();
}

void ProcessRunner::AdvanceStopAll() {
  while (!stop_queue_.empty()) {
    Record& r = records_[stop_queue_.front()];
    if (r.state.status == CommandStatus::kRunning) StopRecord(&r);
    if (r.state.status == CommandStatus::kStopping) return;
    stop_queue_.erase(stop_queue_.begin());
  }
}

bool ProcessRunner::IsIdle() const {
  if (!stop_queue_.empty()) return false;
  for (const Record& r : records_) {
    if (IsAlive(r) || r.state.status == CommandStatus::kRespawnPending) {
      return false;
    }
  }
  return true;
}

void ProcessRunner::OnLeaderExit(Record* r, int wait_status,
                                 Clock::time_point now) {
  // Output written just before the exit is already in the pipes; forward it
  // so it appears before the exit event.
  for (OutputPipe& pipe : r->pipes) ReadPipe(r, &pipe);
  const ExitInfo info = DecodeWaitStatus(wait_status);
  r->state.last_exit = info;
  ++r->state.exit_count;
  r->leader_reaped = true;
  if (r->state.status == CommandStatus::kStopping) {
    // Completed in ReapGroup() once the rest of the group is gone too.
    return;
  }
  r->state.pid = -1;
  r->leader_exit_at = now;
  // Zombies of the group are not "left running".
  int ignored = 0;
  while (::waitpid(-r->pgid, &ignored, WNOHANG) > 0) {
  }
  if (GroupExists(r->pgid)) {
    // E.g. the shell of a pipeline was killed: what it started must not run
    // on beside a respawned copy, nor outlive the sheriff unwatched.
    r->ending_on_its_own = true;
    r->state.status = CommandStatus::kStopping;
    ::kill(-r->pgid, r->spec.stop_signal);
    r->kill_sent = false;
    r->kill_at = now + r->spec.stop_time_allowed;
    Emit("'" + r->spec.name + "' (pid " + std::to_string(r->pgid) + ") ended with " + info.ToString() +
         " but left processes in its group; stopping them with " + SignalName(r->spec.stop_signal) +
         " (SIGKILL after " + Seconds(r->spec.stop_time_allowed) + ")");
    return;
  }
  FinishExit(r);
}

void ProcessRunner::FinishExit(Record* r) {
  r->ending_on_its_own = false;
  const ExitInfo info = r->state.last_exit.value_or(ExitInfo{});
  const auto ran = std::chrono::duration_cast<milliseconds>(r->leader_exit_at - r->started_at);
  if (!r->spec.auto_respawn) {
    r->state.status = CommandStatus::kExited;
    Emit("'" + r->spec.name + "' exited with " + info.ToString() + " after " +
         Seconds(ran));
    return;
  }
  if (r->backoff <= milliseconds(0) ||
      ran >= options_.respawn_backoff_reset_after) {
    r->backoff = options_.respawn_backoff_initial;
  }
  const milliseconds delay = r->backoff;
  r->backoff = std::min(delay * 2, options_.respawn_backoff_max);
  r->respawn_at = std::max(Clock::now(), r->leader_exit_at + delay);
  r->state.status = CommandStatus::kRespawnPending;
  Emit("'" + r->spec.name + "' exited with " + info.ToString() + " after " +
       Seconds(ran) + "; respawning in " + Seconds(delay) + " (respawn #" +
       std::to_string(r->state.respawn_count + 1) + ")");
}

void ProcessRunner::ForgetGroup(Record* r) {
  if (watchdog_ && r->pgid > 0) watchdog_->Forget(r->pgid);
  r->pgid = 0;
}

void ProcessRunner::ReapGroup(Record* r, Clock::time_point now) {
  if (r->pgid <= 0) return;
  int wait_status = 0;
  if (IsAlive(*r) && !r->leader_reaped) {
    // The main process first and by pid: it may have left its group.
    if (::waitpid(r->state.pid, &wait_status, WNOHANG) == r->state.pid) {
      OnLeaderExit(r, wait_status, now);
    }
  }
  // Then whatever of the group was re-parented to us (adopt_orphans).
  pid_t reaped = 0;
  while ((reaped = ::waitpid(-r->pgid, &wait_status, WNOHANG)) > 0) {
    if (reaped == r->state.pid && IsAlive(*r) && !r->leader_reaped) {
      OnLeaderExit(r, wait_status, now);
    }
  }
  const bool group_exists = GroupExists(r->pgid);
  if (r->state.status == CommandStatus::kStopping && r->leader_reaped &&
      (r->kill_sent || !group_exists)) {
    FinishStop(r);
  }
  // Forget a group that is gone, so a later process that happens to reuse
  // the id is never mistaken for (and reaped as) a member of this command.
  if (!IsAlive(*r) && !group_exists) ForgetGroup(r);
}

void ProcessRunner::FinishStop(Record* r) {
  r->state.pid = -1;
  if (r->ending_on_its_own) {
    FinishExit(r);
    return;
  }
  r->state.status = CommandStatus::kStopped;
  std::string how = "unknown status";
  if (const std::optional<ExitInfo>& e = r->state.last_exit) {
    how = e->signal == r->spec.stop_signal ? SignalName(e->signal) + ", its stop signal, as asked"
          : e->signal == SIGKILL && r->kill_sent ? "SIGKILL after stop_time_allowed"
                                                 : e->ToString();
  }
  Emit("'" + r->spec.name + "' stopped; it ended with " + how);
  if (r->restart_pending) {
    r->restart_pending = false;
    StartRecord(r, false);
  }
}

void ProcessRunner::ReadPipe(Record* r, OutputPipe* pipe) {
  char buffer[4096];
  std::size_t total = 0;
  while (pipe->fd.valid() && total < kMaxReadPerPoll) {
    const ssize_t n = ::read(pipe->fd.get(), buffer, sizeof(buffer));
    if (n > 0) {
      total += static_cast<std::size_t>(n);
      for (const std::string& line :
           pipe->lines.Append(std::string_view(buffer, static_cast<std::size_t>(n)))) {
        options_.on_output(r->spec.name, pipe->stream, line);
      }
      continue;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    // EOF (every writer closed) or a read error: this stream is finished.
    if (auto rest = pipe->lines.Flush()) {
      options_.on_output(r->spec.name, pipe->stream, *rest);
    }
    pipe->fd.reset();
  }
}

void ProcessRunner::FlushPipes(Record* r) {
  for (OutputPipe& pipe : r->pipes) {
    ReadPipe(r, &pipe);
    if (auto rest = pipe.lines.Flush()) {
      options_.on_output(r->spec.name, pipe.stream, *rest);
    }
  }
  r->pipes.clear();
}

void ProcessRunner::Poll(milliseconds max_wait) {
  Clock::time_point now = Clock::now();

  // Timers that are due.
  for (Record& r : records_) {
    if (r.state.status == CommandStatus::kRespawnPending && now >= r.respawn_at) {
      StartRecord(&r, true);
    } else if (r.state.status == CommandStatus::kStopping && !r.kill_sent &&
               now >= r.kill_at) {
      ::kill(-r.pgid, SIGKILL);
      if (!r.leader_reaped) ::kill(r.state.pid, SIGKILL);
      r.kill_sent = true;
      Emit("'" + r.spec.name + "' did not stop within " +
           Seconds(r.spec.stop_time_allowed) + "; sent SIGKILL");
    }
  }

  // Sleep until output arrives, the next timer, or the reap interval.
  milliseconds timeout = std::min(std::max(max_wait, milliseconds(0)), kMaxPollInterval);
  for (const Record& r : records_) {
    Clock::time_point due = Clock::time_point::max();
    if (r.state.status == CommandStatus::kRespawnPending) due = r.respawn_at;
    if (r.state.status == CommandStatus::kStopping && !r.kill_sent) due = r.kill_at;
    if (due != Clock::time_point::max()) {
      timeout = std::min(timeout, std::max(milliseconds(0),
                                           std::chrono::ceil<milliseconds>(due - now)));
    }
  }
  std::vector<pollfd> fds;
  std::vector<std::pair<Record*, OutputPipe*>> owners;
  for (Record& r : records_) {
    for (OutputPipe& pipe : r.pipes) {
      if (!pipe.fd.valid()) continue;
      fds.push_back({pipe.fd.get(), POLLIN, 0});
      owners.emplace_back(&r, &pipe);
    }
  }
  // EINTR (a signal for the sheriff) just ends the wait early.
  const int ready = ::poll(fds.data(), fds.size(), static_cast<int>(timeout.count()));
  if (ready > 0) {
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i].revents != 0) ReadPipe(owners[i].first, owners[i].second);
    }
  }
  for (Record& r : records_) {
    r.pipes.erase(std::remove_if(r.pipes.begin(), r.pipes.end(),
                                 [](const OutputPipe& p) { return !p.fd.valid(); }),
                  r.pipes.end());
  }

  now = Clock::now();
  for (Record& r : records_) ReapGroup(&r, now);
  AdvanceStopAll();
  if (watchdog_ && watchdog_->Check()) {
    Emit("the watchdog process had ended; started a new one (pid " + std::to_string(watchdog_->pid()) + ")");
  }
}

}  // namespace vimot::sheriff

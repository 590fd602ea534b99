#pragma once
// Makes a sheriff's commands die with it, even when it is killed with
// SIGKILL and has no chance to stop them.
//
// PR_SET_PDEATHSIG (set in every command's child) reaches only the process
// the sheriff forked; a command's shell pipeline or the children a program
// starts would survive. So a small watchdog process, forked from the sheriff
// before its first command, holds one end of a socket whose other end only
// the sheriff holds, and learns every command's process group through it.
// When the sheriff dies, for whatever reason, the socket reads EOF and the
// watchdog sends each group its stop signal, then SIGKILL after its
// stop_time_allowed, and exits. A sheriff that shuts down normally stops its
// commands itself and tells the watchdog to forget them first.
//
// The watchdog runs in its own process group (a Ctrl-C in the terminal
// reaches only the sheriff) and ignores SIGINT and SIGHUP. If it dies, the
// sheriff starts a new one and tells it every group again (Check()).

#include <sys/types.h>

#include <chrono>
#include <map>

#include "procs/sheriff/unique_fd.h"

namespace vimot::sheriff {

class GroupWatchdog {
 public:
  /// Forks the watchdog; throws std::runtime_error if it cannot. The calling
  /// process must be single-threaded (the child runs ordinary C++ code).
  GroupWatchdog();
  /// Tells the watchdog to forget every group, closes the socket, reaps it.
  ~GroupWatchdog();
  GroupWatchdog(const GroupWatchdog&) = delete;
  GroupWatchdog& operator=(const GroupWatchdog&) = delete;

  /// Stop process group `pgid` with `stop_signal`, then SIGKILL after
  /// `stop_time_allowed`, should the sheriff die.
  void Watch(pid_t pgid, int stop_signal, std::chrono::milliseconds stop_time_allowed);
  /// The group has ended: never signal its id (it may be reused).
  void Forget(pid_t pgid);
  /// Starts a new watchdog if this one has died, and tells it every watched
  /// group. True if it had died.
  bool Check();

  pid_t pid() const { return pid_; }

 private:
  struct Group {
    int stop_signal;
    std::chrono::milliseconds stop_time_allowed;
  };
  void Spawn();
  void Reap();
  void Send(int op, pid_t pgid, const Group& group);

  std::map<pid_t, Group> groups_;
  UniqueFd socket_;
  pid_t pid_{-1};
};

}  // namespace vimot::sheriff

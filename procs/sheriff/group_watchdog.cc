#include "procs/sheriff/group_watchdog.h"

#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>

namespace vimot::sheriff {

namespace {

enum Op : int32_t { kWatch = 1, kForget = 2, kForgetAll = 3 };

// Fixed-size, so the watchdog can reassemble messages a stream splits.
struct Message {
  int32_t op;
  int32_t pgid;
  int32_t stop_signal;
  int32_t stop_time_ms;
};

// The watchdog's whole life: collect groups until EOF, then stop them.
[[noreturn]] void RunWatchdog(int fd) {
  std::map<pid_t, Message> groups;
  Message m{};
  std::size_t have = 0;
  while (true) {
    const ssize_t n = ::read(fd, reinterpret_cast<char*>(&m) + have, sizeof(m) - have);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // EOF: the sheriff is gone (or said goodbye)
    have += static_cast<std::size_t>(n);
    if (have < sizeof(m)) continue;
    have = 0;
    if (m.op == kWatch) groups[m.pgid] = m;
    if (m.op == kForget) groups.erase(m.pgid);
    if (m.op == kForgetAll) groups.clear();
  }
  if (groups.empty()) ::_exit(0);
  const char note[] = "[sheriff watchdog] the sheriff ended without stopping its commands; stopping them\n";
  const ssize_t ignored = ::write(STDERR_FILENO, note, sizeof(note) - 1);
  (void)ignored;
  int32_t wait_ms = 0;
  for (const auto& [pgid, g] : groups) {
    ::kill(-pgid, g.stop_signal);
    wait_ms = std::max(wait_ms, g.stop_time_ms);
  }
  // Poll until every group has ended or the longest stop_time_allowed has
  // passed. Zombies count as alive (only their parent could reap them).
  for (int32_t waited = 0; waited < wait_ms; waited += 20) {
    bool any = false;
    for (const auto& entry : groups) any = any || ::kill(-entry.first, 0) == 0;
    if (!any) ::_exit(0);
    ::usleep(20000);
  }
  for (const auto& entry : groups) ::kill(-entry.first, SIGKILL);
  ::_exit(0);
}

}  // namespace

GroupWatchdog::GroupWatchdog() { Spawn(); }

GroupWatchdog::~GroupWatchdog() {
  Send(kForgetAll, 0, Group{0, {}});
  socket_.reset();
  Reap();
}

void GroupWatchdog::Spawn() {
  int fds[2] = {-1, -1};
  // CLOEXEC: commands must not inherit the sheriff's end, or the watchdog
  // would not see EOF while any of them lives.
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0) {
    throw std::runtime_error(std::string("watchdog socketpair: ") + std::strerror(errno));
  }
  UniqueFd ours(fds[0]), theirs(fds[1]);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("watchdog fork: ") + std::strerror(errno));
  if (pid == 0) {
    ::setpgid(0, 0);
    ::signal(SIGINT, SIG_IGN);
    ::signal(SIGHUP, SIG_IGN);
    ::signal(SIGTERM, SIG_DFL);
    sigset_t none;
    ::sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    // Keep stdio and our end only: a copy of the sheriff's end (or of a
    // command's pipe) here would hide the EOF the watchdog waits for.
    const int fd = ::dup2(theirs.get(), 3) == 3 ? 3 : -1;
    if (fd < 0) ::_exit(1);
    ::close_range(4, ~0U, 0);
    RunWatchdog(fd);
  }
  socket_ = std::move(ours);
  pid_ = pid;
}

void GroupWatchdog::Reap() {
  if (pid_ <= 0) return;
  int status = 0;
  while (::waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
}

void GroupWatchdog::Send(int op, pid_t pgid, const Group& group) {
  if (!socket_.valid()) return;
  const Message m{op, static_cast<int32_t>(pgid), group.stop_signal,
                  static_cast<int32_t>(std::min<int64_t>(group.stop_time_allowed.count(), INT32_MAX))};
  // MSG_NOSIGNAL: a dead watchdog must not SIGPIPE the sheriff; Check()
  // notices and replaces it.
  while (::send(socket_.get(), &m, sizeof(m), MSG_NOSIGNAL) < 0 && errno == EINTR) {
  }
}

void GroupWatchdog::Watch(pid_t pgid, int stop_signal, std::chrono::milliseconds stop_time_allowed) {
  const Group g{stop_signal, stop_time_allowed};
  groups_[pgid] = g;
  Send(kWatch, pgid, g);
}

void GroupWatchdog::Forget(pid_t pgid) {
  if (groups_.erase(pgid) > 0) Send(kForget, pgid, Group{0, {}});
}

bool GroupWatchdog::Check() {
  int status = 0;
  if (pid_ <= 0 || ::waitpid(pid_, &status, WNOHANG) != pid_) return false;
  pid_ = -1;
  socket_.reset();
  Spawn();
  for (const auto& [pgid, g] : groups_) Send(kWatch, pgid, g);
  return true;
}

}  // namespace vimot::sheriff

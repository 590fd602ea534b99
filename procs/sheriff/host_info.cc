#include "procs/sheriff/host_info.h"

#include <unistd.h>

#include <climits>
#include <vector>

namespace vimot::sheriff {

std::string HostName() {
  std::vector<char> name(HOST_NAME_MAX + 1, '\0');
  if (::gethostname(name.data(), name.size() - 1) != 0 || name[0] == '\0') return "localhost";
  return name.data();
}

std::optional<std::string> ExecutableDirectory() {
  std::vector<char> path(PATH_MAX + 1, '\0');
  const ssize_t n = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (n <= 0) return std::nullopt;
  const std::string exe(path.data(), static_cast<std::size_t>(n));
  const std::size_t slash = exe.rfind('/');
  if (slash == std::string::npos) return std::nullopt;
  return slash == 0 ? "/" : exe.substr(0, slash);
}

}  // namespace vimot::sheriff

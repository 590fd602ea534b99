#pragma once
// This machine's name and this executable's folder, for the sheriff and
// deputy command lines.

#include <optional>
#include <string>

namespace vimot::sheriff {

/// gethostname(), or "localhost" when it fails.
std::string HostName();

/// Directory of the running executable (so configs can say
/// ${VIMOT_BIN}/vimot-sim), nullopt if /proc/self/exe cannot be read.
std::optional<std::string> ExecutableDirectory();

}  // namespace vimot::sheriff

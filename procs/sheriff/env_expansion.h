#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace vimot::sheriff {

/// Returns the value of an environment variable, or nullopt when undefined.
using EnvironmentLookup =
    std::function<std::optional<std::string>(const std::string& name)>;

/// Lookup in this process's environment (getenv).
std::optional<std::string> LookupProcessEnvironment(const std::string& name);

/// Expands environment variables in a command's exec string, the way procman
/// configs refer to install locations ("${VIMOT_BIN}/vimot-sim") instead of
/// absolute paths:
///  * `${NAME}` and `$NAME` (NAME = [A-Za-z_][A-Za-z0-9_]*) are replaced by
///    the value from `lookup`;
///  * `$$` is a literal `$`, so a shell variable can still reach `/bin/sh`
///    unexpanded (`for f in a b; do echo $$f; done`);
///  * a `$` followed by anything else (`$1`, `$?`, `$(`) is kept as is.
/// Throws std::runtime_error naming the variable when one is undefined, and
/// on a malformed `${...}` (unterminated, empty or not a valid name).
std::string ExpandEnvironmentVariables(std::string_view text,
                                       const EnvironmentLookup& lookup);

}  // namespace vimot::sheriff

// ${VAR} / $VAR expansion of exec strings.
#include <catch2/catch.hpp>

#include <map>
#include <string>

#include "procs/sheriff/env_expansion.h"

using namespace vimot::sheriff;

namespace {

EnvironmentLookup Env(std::map<std::string, std::string> vars) {
  return [vars](const std::string& name) -> std::optional<std::string> {
    const auto it = vars.find(name);
    if (it == vars.end()) return std::nullopt;
    return it->second;
  };
}

std::string ErrorOf(const std::string& text) {
  try {
    ExpandEnvironmentVariables(text, Env({}));
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("both reference forms expand, shell syntax is left alone") {
  const auto env = Env({{"VIMOT_BIN", "/opt/vimot/bin"}, {"N", "3"}, {"EMPTY", ""}});
  CHECK(ExpandEnvironmentVariables("${VIMOT_BIN}/vimot-sim --n $N", env) ==
        "/opt/vimot/bin/vimot-sim --n 3");
  CHECK(ExpandEnvironmentVariables("$VIMOT_BIN/x${N}y", env) == "/opt/vimot/bin/x3y");
  CHECK(ExpandEnvironmentVariables("a${EMPTY}b", env) == "ab");
  // A name runs as long as name characters do.
  CHECK(ExpandEnvironmentVariables("$N.log $N-x", env) == "3.log 3-x");
  // $$ is a literal $, for variables meant for /bin/sh.
  CHECK(ExpandEnvironmentVariables("for f in a; do echo $$f; done", env) ==
        "for f in a; do echo $f; done");
  CHECK(ExpandEnvironmentVariables("echo $1 $? $(date) 100$", env) ==
        "echo $1 $? $(date) 100$");
  CHECK(ExpandEnvironmentVariables("", env).empty());
}

TEST_CASE("an undefined variable is an error naming it") {
  const std::string braces = ErrorOf("${VIMOT_BIN}/vimot-sim");
  CHECK(braces.find("undefined environment variable 'VIMOT_BIN'") != std::string::npos);
  CHECK(braces.find("${VIMOT_BIN}/vimot-sim") != std::string::npos);
  CHECK(ErrorOf("run $DATA_DIR/x").find("'DATA_DIR'") != std::string::npos);
}

TEST_CASE("malformed references are errors") {
  CHECK(ErrorOf("${VIMOT_BIN/x").find("unterminated '${'") != std::string::npos);
  CHECK(ErrorOf("a ${} b").find("'${}' is not a valid") != std::string::npos);
  CHECK(ErrorOf("${1X}").find("'${1X}' is not a valid") != std::string::npos);
}

TEST_CASE("the process environment lookup reads getenv") {
  ::setenv("VIMOT_SHERIFF_TEST_VAR", "value", 1);
  ::unsetenv("VIMOT_SHERIFF_TEST_UNSET");
  CHECK(ExpandEnvironmentVariables("<$VIMOT_SHERIFF_TEST_VAR>",
                                   LookupProcessEnvironment) == "<value>");
  CHECK_THROWS_WITH(
      ExpandEnvironmentVariables("$VIMOT_SHERIFF_TEST_UNSET", LookupProcessEnvironment),
      Catch::Contains("VIMOT_SHERIFF_TEST_UNSET"));
}

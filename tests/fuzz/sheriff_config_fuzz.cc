// libFuzzer target: the procman config parser of vimot-sheriff on arbitrary
// text, then what the sheriff does with a config before starting anything
// (listing it, selecting a script's or a group's commands). A ConfigParseError is the
// expected outcome for most inputs; any other exception, a crash or a stack
// overflow is a finding.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "procs/sheriff/script_executor.h"
#include "procs/sheriff/sheriff_config_parser.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const vimot::sheriff::SheriffConfig config = vimot::sheriff::ParseSheriffConfig(text, "fuzz.pmd");
    // What vimot-sheriff does next: --list, or select a script or a group
    // (one of each, as one run does).
    vimot::sheriff::DescribeConfig(config);
    if (!config.scripts().empty()) {
      vimot::sheriff::ScriptExecutor::CommandsStartedBy(config, config.scripts().back().name);
    }
    if (!config.groups().empty()) config.CommandsInGroup(config.groups().back().name);
  } catch (const vimot::sheriff::ConfigParseError&) {
  }
  return 0;
}

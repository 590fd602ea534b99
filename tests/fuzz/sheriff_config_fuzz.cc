// libFuzzer target: the procman config parser of vimot-sheriff on arbitrary
// text, then what the sheriff does with a config before starting anything
// (listing it, collecting each script's commands). A ConfigParseError is the
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
    vimot::sheriff::DescribeConfig(config);
    for (const vimot::sheriff::ScriptSpec& s : config.scripts()) {
      vimot::sheriff::ScriptExecutor::CommandsStartedBy(config, s.name);
    }
    for (const vimot::sheriff::GroupSpec& g : config.groups()) config.CommandsInGroup(g.name);
  } catch (const vimot::sheriff::ConfigParseError&) {
  }
  return 0;
}

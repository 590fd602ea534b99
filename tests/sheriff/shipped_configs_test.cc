// The shipped sheriff configs (sheriff_configs/*.pmd) load without warnings,
// start the processes their scenario needs and name config files that exist.
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "procs/sheriff/sheriff_config_parser.h"

using namespace vimot::sheriff;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

void check_config(const std::string& pmd, const std::vector<std::string>& expected_commands,
                  const std::vector<std::string>& config_files) {
  INFO(pmd);
  const SheriffConfig config = LoadSheriffConfig(source_path("sheriff_configs/" + pmd));
  CHECK(config.warnings().empty());
  std::vector<std::string> names;
  std::string execs;
  for (const CommandSpec& c : config.commands()) {
    names.push_back(c.name);
    execs += c.exec + " \n";  // each argument ends with a space
  }
  CHECK(names == expected_commands);
  for (const std::string& file : config_files) {
    INFO(file);
    CHECK(execs.find("${VIMOT_CONFIG}/" + file + " ") != std::string::npos);
    CHECK(std::ifstream(source_path("config/" + file)).good());
  }
  REQUIRE(config.scripts().size() == 1);
  CHECK(config.scripts()[0].name == "run");
}

}  // namespace

TEST_CASE("shipped sheriff configs parse") {
  check_config("sim_demo.pmd", {"logger", "vins", "target_filter", "sim"}, {"target_filter.yaml"});
  // config/object_tracker.yaml comes with the object tracker (issue 5, tracker branch).
  check_config("sim_mono.pmd", {"logger", "vins", "object_tracker", "scale_estimator", "sim"},
               {"vins_mono.yaml", "scale_estimator.yaml"});
  check_config("euroc.pmd", {"logger", "vins", "feature_tracker", "euroc_player"},
               {"vins_euroc.yaml", "feature_tracker.yaml"});
  check_config("sim_pixels.pmd", {"logger", "vins", "target_filter", "feature_tracker", "sim"},
               {"target_filter.yaml"});
  check_config("sim_segmented.pmd",
               {"logger", "vins", "target_filter", "segmenter", "mask_filter", "feature_tracker", "sim"},
               {"target_filter.yaml"});
  check_config("sim_mono_segmented.pmd",
               {"logger", "vins", "object_tracker", "scale_estimator", "segmenter", "mask_filter", "feature_tracker",
                "sim"},
               {"vins_mono.yaml", "object_tracker.yaml", "scale_estimator.yaml", "segmenter_mono.yaml",
                "mask_filter_mono.yaml", "feature_tracker_segmented_mono.yaml"});
}

TEST_CASE("the two-host layout puts each command on its machine") {
  check_config("two_hosts.pmd", {"logger", "vins", "target_filter", "sim"}, {"target_filter.yaml"});
  const SheriffConfig config = LoadSheriffConfig(source_path("sheriff_configs/two_hosts.pmd"));
  std::map<std::string, std::string> host;
  for (const CommandSpec& c : config.commands()) host[c.name] = c.host;
  CHECK(host["logger"] == "ground");
  CHECK(host["vins"] == "vehicle");
  CHECK(host["target_filter"] == "vehicle");
  CHECK(host["sim"] == "vehicle");
}

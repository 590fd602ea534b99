// The shipped sheriff configs (sheriff_configs/*.pmd) load without warnings,
// start the processes their scenario needs, name config files that exist and
// only vimot executables that the build makes.
#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "procs/sheriff/sheriff_config_parser.h"

using namespace vimot::sheriff;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

// The configs the test cases below check; a .pmd in the folder but not
// here fails.
const std::set<std::string> kChecked = {"sim_demo.pmd",    "sim_mono.pmd",      "euroc.pmd",
                                        "sim_pixels.pmd",  "two_hosts.pmd",     "live_stereo.pmd",
                                        "live_mono.pmd",   "log_playback.pmd",  "two_hosts_live.pmd"};

void check_config(const std::string& pmd, const std::vector<std::string>& expected_commands,
                  const std::vector<std::string>& config_files) {
  INFO(pmd);
  CHECK(kChecked.count(pmd) == 1);
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
  // Onboard the target filter is the VIO: no vins beside it.
  check_config("live_stereo.pmd",
               {"logger", "target_filter", "feature_tracker", "segmenter", "mask_filter", "imu", "camera"},
               {"target_filter_live.yaml", "feature_tracker_live.yaml", "segmenter.yaml", "mask_filter.yaml",
                "imu_mip.yaml", "camera.yaml"});
  check_config("live_mono.pmd",
               {"logger", "vins", "object_tracker", "scale_estimator", "feature_tracker", "segmenter", "mask_filter",
                "imu", "camera"},
               {"vins_live_mono.yaml", "object_tracker.yaml", "scale_estimator.yaml", "feature_tracker_live_mono.yaml",
                "segmenter_mono.yaml", "mask_filter_mono.yaml", "imu_mip.yaml", "camera_mono.yaml"});
  // The estimator configs come from the environment (simulated or real log).
  check_config("log_playback.pmd", {"logger", "vins", "target_filter", "player"}, {});
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

TEST_CASE("the live two-host layout: sensors and estimators on the vehicle, a logger on each host") {
  check_config("two_hosts_live.pmd",
               {"vehicle_logger", "ground_logger", "target_filter", "feature_tracker", "segmenter", "mask_filter", "imu",
                "camera"},
               {"target_filter_live.yaml", "feature_tracker_live.yaml", "segmenter.yaml", "mask_filter.yaml",
                "imu_mip.yaml", "camera.yaml"});
  const SheriffConfig config = LoadSheriffConfig(source_path("sheriff_configs/two_hosts_live.pmd"));
  for (const CommandSpec& c : config.commands()) {
    INFO(c.name);
    CHECK(c.host == (c.name == "ground_logger" ? "ground" : "vehicle"));
  }
}

TEST_CASE("every shipped config is checked and names only executables the build makes") {
  int executables = 0;
  for (const auto& entry : std::filesystem::directory_iterator(source_path("sheriff_configs"))) {
    if (entry.path().extension() != ".pmd") continue;
    const std::string pmd = entry.path().filename().string();
    INFO(pmd);
    CHECK(kChecked.count(pmd) == 1);
    const SheriffConfig config = LoadSheriffConfig(entry.path().string());
    const std::regex vimot_exec(R"(\$\{VIMOT_BIN\}/(\S+))");
    for (const CommandSpec& c : config.commands()) {
      for (std::sregex_iterator m(c.exec.begin(), c.exec.end(), vimot_exec), end; m != end; ++m) {
        const std::string path = std::string(VIMOT_BIN_DIR) + "/" + (*m)[1].str();
        INFO(c.name << ": " << path);
        CHECK(::access(path.c_str(), X_OK) == 0);
        ++executables;
      }
    }
  }
  CHECK(executables >= 30);
}

// vimot-log-replay: replays a recorded LCM run through the vins and/or
// target_filter Nodes, deterministically and as fast as the CPU allows (no
// LCM network), and compares every output byte for byte with what the live
// processes published into the same log. The logic is log_replay.h.
#include <iomanip>
#include <iostream>

#include "common/process/arg_parser.h"
#include "common/process/process.h"
#include "procs/log_replay/log_replay.h"

namespace {

int run(int argc, const char* const* argv) {
  vimot::ArgParser args("vimot-log-replay",
                        "Feeds the inputs recorded in an LCM log (IMU, FEATURES, GROUND_TRUTH; names from\n"
                        "each config's channels) through the same Nodes as the vins / target_filter\n"
                        "processes, in log order, in one thread, as fast as the CPU allows, and compares\n"
                        "each output (VINS_STATE; NAV_STATE, TARGET_STATE, TARGET_PREDICTION) byte for byte\n"
                        "with the messages the live processes logged, in order (a replayed message the log\n"
                        "lacks, lost by the logger, is counted as not logged; a copy a respawned process\n"
                        "published again after catching up, as republished). An undisturbed live run, and one\n"
                        "with processes respawned with --catch-up-log, is reproduced bit for bit\n"
                        "(docs/record_replay.md).\n"
                        "Exit status: 0 all outputs identical; 3 a difference (first one printed); 2 nothing\n"
                        "to compare (no recorded outputs); 1 bad input.");
  args.set_positional("LOG", "LCM log of a live run (lcm-logger, scripts/record.sh, scripts/demo.sh)", 1, 1);
  args.add_option("vins", "CONFIG", "replay vins with this config (e.g. config/vins.yaml)");
  args.add_option("target-filter", "CONFIG", "replay target_filter with this config (e.g. config/target_filter.yaml)");
  args.add_option("perturb-seed", "N", "as the processes' --perturb-seed (overrides init.perturb_seed)");
  args.add_option("out", "FILE",
                  "write the replayed outputs and the log's ground truth to this LCM log (event time = utime),\n"
                  "for vimot-log-eval");
  args.add_option("from-utime", "UTIME",
                  "feed only the inputs at or after this utime: the Nodes start as a process started then\n"
                  "would (compare only the recorded outputs from there)");
  if (!args.parse(argc, argv)) return 0;

  vimot::ReplaySetup setup;
  if (args.given("vins")) setup.vins_config = args.get("vins");
  if (args.given("target-filter")) setup.target_filter_config = args.get("target-filter");
  if (!args.given("vins") && !args.given("target-filter")) {
    throw vimot::ArgError("vimot-log-replay: give --vins CONFIG and/or --target-filter CONFIG");
  }
  if (args.given("perturb-seed")) {
    const long long seed = args.get_int("perturb-seed");
    if (seed < 0) throw vimot::ArgError("vimot-log-replay: --perturb-seed must be >= 0");
    setup.perturb_seed = seed;
  }
  if (args.given("out")) setup.out_log = args.get("out");
  if (args.given("from-utime")) {
    setup.from_utime = args.get_int("from-utime");
    if (setup.from_utime < 0) throw vimot::ArgError("vimot-log-replay: --from-utime must be >= 0");
  }

  const vimot::ReplayReport report = vimot::replay_log(args.positionals()[0], setup);
  std::cout << "replayed " << report.inputs << " inputs of " << report.events << " log events ("
            << report.malformed << " malformed, skipped); the Nodes reported " << report.node_errors << " errors, "
            << report.node_dropped << " dropped or lost\n";
  std::cout << std::fixed << std::setprecision(2) << report.data_span_s << " s of data in " << report.cpu_s
            << " s CPU";
  if (report.cpu_s > 0) std::cout << " (" << std::setprecision(1) << report.data_span_s / report.cpu_s << "x real time)";
  std::cout << "\n";
  std::cout << std::left << std::setw(22) << "channel" << std::right << std::setw(10) << "recorded" << std::setw(10)
            << "replayed" << std::setw(11) << "identical" << std::setw(12) << "not logged" << std::setw(13) << "republished"
            << "  first difference\n";
  int64_t recorded = 0;
  for (const vimot::ChannelComparison& c : report.channels) {
    recorded += c.recorded;
    std::cout << std::left << std::setw(22) << c.channel << std::right << std::setw(10) << c.recorded << std::setw(10)
              << c.replayed << std::setw(11) << c.identical << std::setw(12) << c.not_logged << std::setw(13)
              << c.republished << "  ";
    if (c.equal()) {
      std::cout << "none\n";
    } else {
      std::cout << "message " << c.first_difference;
      if (c.first_difference_utime >= 0) std::cout << " (utime " << c.first_difference_utime << ")";
      std::cout << "\n";
    }
  }
  if (recorded == 0) {
    std::cerr << "vimot-log-replay: the log holds no recorded outputs to compare with\n";
    return 2;
  }
  std::cout << (report.identical() ? "bit for bit identical to the live run (every logged output)\n"
                                    : "DIFFERS from the live run\n");
  return report.identical() ? 0 : 3;
}

}  // namespace

int main(int argc, char** argv) {
  return vimot::run_process_main([&] { return run(argc, argv); });
}

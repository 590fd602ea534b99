// vimot-vio-eval: Monte-Carlo accuracy and consistency of the VIO estimator
// on the simulator, offline (the vins process's Node fed the simulator's
// messages as over LCM, no network: vio_run.h), configured from the same vins config
// as the `vins` process. Runs are independent std::threads; run i uses
// simulator seed first_seed + i. Prints a per-run table and the average;
// --out writes TUM trajectories, per-frame error CSVs and summaries.
#include <optional>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>

#include "common/config/config.h"
#include "common/eval/evaluation_setup.h"
#include "common/eval/machine.h"
#include "common/eval/progress.h"
#include "common/eval/report.h"
#include "common/eval/sim_runner.h"
#include "common/eval/writers.h"
#include "common/process/arg_parser.h"
#include "common/process/logger.h"
#include "common/sim/simulator.h"
#include "procs/eval/monte_carlo_args.h"
#include "procs/eval/vio_run.h"

namespace {

using namespace vimot;

using eval::hms;
using eval::ProgressBar;

std::string seed_name(uint64_t seed) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "seed%03llu", static_cast<unsigned long long>(seed));
  return buf;
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-vio-eval",
                 "Monte-Carlo evaluation of the VIO estimator on the simulator, offline: the vins\n"
                 "process's logic fed the simulator's messages as over LCM, with no network.\n"
                 "Run i simulates with seed first_seed+i and starts from the truth perturbed by a\n"
                 "sample of P0 (seed derived from the simulator seed). Prints per run and on\n"
                 "average: position RMSE [m], orientation RMSE [deg], NEES of position and\n"
                 "orientation (ideal 3), path length, per-frame CPU time, update counts, and\n"
                 "(row 'pred') the RMSE the filter's own covariance predicts, sqrt(mean tr P).\n"
                 "Exit status: 0, 2 if a run diverged, 1 on bad input.");
  args.add_option("sim-config", "FILE", "simulator scenario", "config/sim_paper.yaml");
  args.add_option("vins-config", "FILE", "estimator config (as the vins process loads it)", "config/vins.yaml");
  eval::add_monte_carlo_args(args, "Monte-Carlo runs", "30");
  args.add_option("out", "DIR", "write per-run TUM estimate/truth and error CSV, summary.json, summary.csv");
  args.add_flag("no-perturb", "start every run exactly at the truth");
  args.add_flag("quiet", "no progress bar");
  args.add_option("log-level", "LEVEL", "debug|info|warn|error", "info");
  if (!args.parse(argc, argv)) return 0;
  set_log_name("vio-eval");
  set_log_level(parse_log_level(args.get("log-level")));

  const std::string sim_path = args.get("sim-config");
  const std::string vins_path = args.get("vins-config");
  const eval::MonteCarloArgs mca = eval::read_monte_carlo_args(args);
  const eval::EvaluationSetup setup = eval::load_evaluation_setup(sim_path, vins_path, mca.duration_s);
  for (const std::string& m : setup.model_mismatches) log_warn("estimator model differs from the simulator: ", m);
  const sim::SimConfig& sim_cfg = setup.sim;
  const estimator::VioOptions& options = setup.vio;

  eval::MonteCarloOptions mc;
  mc.runs = mca.runs;
  mc.first_seed = mca.first_seed;
  mc.threads = std::min(mca.threads, mc.runs);
  mc.perturb = !args.flag("no-perturb");
  if (mca.perturb_seed) {
    if (*mca.perturb_seed == 0) mc.perturb = false;
    mc.fixed_perturb_seed = *mca.perturb_seed;
  }
  const std::string out_dir = args.get("out");
  mc.keep_samples = !out_dir.empty();
  mc.pixels = mca.pixels;
  mc.box_chain = mca.box_chain;
  if (!out_dir.empty()) std::filesystem::create_directories(out_dir);

  log_info("scenario ", sim::to_string(sim_cfg.scenario), " (", sim_path, "), estimator ", vins_path, ": ", mc.runs,
           " runs from seed ", mc.first_seed, " on ", mc.threads, " threads, ",
           mc.perturb ? "perturbed start" : "start at the truth");

  const auto t0 = std::chrono::steady_clock::now();
  ProgressBar bar(!args.flag("quiet"));
  const std::vector<eval::SimRunResult> results =
      eval::run_monte_carlo(sim_cfg, options, mc, [&bar](const eval::MonteCarloProgress& p) { bar.update(p); },
                            input_guard_options_from_config(Config::load_file(vins_path)));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const eval::MachineInfo machine = eval::machine_info();
  std::cout << eval::results_table(results);
  std::cout << "wall time " << hms(wall) << " on " << mc.threads << " threads; machine: " << machine.nproc
            << " CPUs, " << machine.cpu_model << "\n";

  if (!out_dir.empty()) {
    for (const eval::SimRunResult& r : results) {
      const std::string base = out_dir + "/" + seed_name(r.sim_seed);
      const std::string what = "simulator seed " + std::to_string(r.sim_seed) + ", perturbation seed " +
                               std::to_string(r.perturb_seed) + ", " + sim_path;
      eval::write_tum(base + "_estimate.tum", eval::estimate_poses(r.samples),
                      "vimot-vio-eval estimate after each camera update (t x y z qx qy qz qw, Hamilton q_ItoG)\n" + what);
      eval::write_tum(base + "_truth.tum", eval::truth_poses(r.samples),
                      "vimot-vio-eval ground truth at the estimate times (t x y z qx qy qz qw, Hamilton q_ItoG)\n" +
                          what);
      eval::write_errors_csv(base + "_errors.csv", eval::errors_of(r.samples));
    }
    eval::RunContext ctx;
    ctx.sim_config = sim_path;
    ctx.vins_config = vins_path;
    ctx.first_seed = mc.first_seed;
    ctx.perturb = mc.perturb;
    ctx.threads = mc.threads;
    ctx.wall_s = wall;
    ctx.machine = machine;
    eval::write_text_file(out_dir + "/summary.json", eval::summary_json(results, ctx));
    eval::write_text_file(out_dir + "/summary.csv", eval::summary_csv(results));
    std::cout << "wrote " << out_dir << "/{summary.json, summary.csv, seedNNN_{estimate.tum, truth.tum, errors.csv}}\n";
  }
  for (const auto& r : results) {
    if (r.diverged) return 2;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-vio-eval", argc, argv, run); }

// vimot-target-eval: the σ_t sweep of Eckenhoff et al., "Schmidt-EKF-based
// Visual-Inertial Moving Object Tracking", Sec. IV (Tables I and II), on the
// simulator, offline (the target_filter process's Node fed the simulator's
// messages as over LCM, no network: target_run.h): joint robot + target filter (EKF / SKF,
// global / local) and the VIO-only reference, N Monte-Carlo runs per cell.
// Run i of every cell uses simulator seed first_seed + i and the perturbed
// IMU start of vimot-vio-eval; the target starts from its own features (or
// the truth: --target-init). --pixels: the frames come from the rendered
// images through the feature tracker, as vimot-vio-eval --pixels.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "common/config/config.h"
#include "common/eval/evaluation_setup.h"
#include "common/eval/machine.h"
#include "common/eval/progress.h"
#include "common/eval/target_eval.h"
#include "common/eval/writers.h"
#include "common/process/arg_parser.h"
#include "common/process/logger.h"
#include "common/sim/simulator.h"
#include "common/target/target_filter_config.h"
#include "procs/eval/monte_carlo_args.h"
#include "procs/eval/target_run.h"

namespace {

using namespace vimot;

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

// --merge: the tables of several earlier --out folders as one sweep.
int merge(const ArgParser& args) {
  std::vector<eval::TargetCell> cells;
  for (const std::string& dir : split(args.get("merge"))) {
    for (eval::TargetCell& c : eval::read_target_cells(dir + "/summary.json")) cells.push_back(std::move(c));
  }
  if (cells.empty()) throw ArgError("--merge: no cells in " + args.get("merge"));
  std::cout << eval::target_tables(cells);
  int runs = 0;
  double wall = 0.0;
  for (const auto& c : cells) {
    for (const auto& r : c.runs) {
      ++runs;
      wall += r.wall_s;
    }
  }
  std::cout << "\n" << cells.size() << " cells, " << runs << " runs merged from " << args.get("merge") << " ("
            << eval::hms(wall) << " of single-thread run time)\n";
  const std::string out_dir = args.get("out");
  if (!out_dir.empty()) {
    std::filesystem::create_directories(out_dir);
    eval::TargetSweepOptions o;
    o.runs = static_cast<int>(cells.front().runs.size());
    eval::write_text_file(out_dir + "/summary.json",
                          eval::target_summary_json(cells, args.get("sim-config"), args.get("vins-config"),
                                                    args.get("target-config"), o, wall));
    eval::write_text_file(out_dir + "/summary.csv", eval::target_summary_csv(cells));
    std::cout << "wrote " << out_dir << "/{summary.json, summary.csv}\n";
  }
  return 0;
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-target-eval",
                 "Monte-Carlo σ_t sweep of the joint robot + target filter on the simulator (paper\n"
                 "Tables I and II), offline: the target_filter process's logic fed the simulator's\n"
                 "messages as over LCM, with no network. Per σ_t × mode (ekf, skf) × representation\n"
                 "(global, local), plus the VIO-only row: average over runs of the RMSE of the\n"
                 "target pose in the IMU frame, the target pose in the world and the IMU pose\n"
                 "(m / deg), over the camera frames after the target initialisation, and NEES.\n"
                 "Options not swept come from the target config's `target:` section. Per run (up to\n"
                 "12 runs in all) also how well the target was tracked: frames with a target\n"
                 "estimate, with target features, with a target update, the longest gap.\n"
                 "Exit status: 0, 2 if a run diverged, 1 on bad input.");
  args.add_option("sim-config", "FILE", "simulator scenario (config/sim_paper.yaml: the paper's semicircle)",
                  "config/sim_paper_rc_car.yaml");
  args.add_option("vins-config", "FILE", "estimator config", "config/vins.yaml");
  args.add_option("target-config", "FILE", "target filter config (`target:` section)", "config/target_filter.yaml");
  args.add_option("sigmas", "LIST", "comma-separated σ_t values", "0.001,0.005,0.01,0.05,0.1,0.5");
  args.add_option("modes", "LIST", "comma-separated: ekf,skf,adaptive (adaptive: σ_t estimated from the cell's on)",
                  "ekf,skf");
  args.add_option("representations", "LIST", "comma-separated: global,local", "global,local");
  args.add_flag("no-vio-only", "skip the VIO-only row");
  args.add_option("target-init", "MODE",
                  "features | ground_truth: how the target starts (overrides the target config's\n"
                  "init.mode); features: the filter's own target frame, compared through the fixed\n"
                  "transform to the true one at its first estimate (printed, and in summary.json)");
  eval::add_monte_carlo_args(args, "Monte-Carlo runs per cell", "30");
  args.add_option("out", "DIR", "write summary.json and summary.csv");
  args.add_option("merge", "DIRS",
                  "run nothing: tabulate the comma-separated --out folders of earlier runs together\n"
                  "(a sweep run in parts, e.g. one σ_t per run); with --out also writes the merged\n"
                  "summary.json / summary.csv");
  args.add_flag("errors",
                "with --out: also write every run's per-frame target errors with 3σ bounds\n"
                "(DIR/errors/<mode>_<repr>_<σ_t>_seedNNN_target_in_{imu,world}.csv, the columns of\n"
                "vimot-vio-eval's errors.csv, for scripts/plot_errors.py)");
  args.add_flag("quiet", "no progress bar");
  args.add_option("log-level", "LEVEL", "debug|info|warn|error", "warn");
  if (!args.parse(argc, argv)) return 0;
  set_log_name("target-eval");
  set_log_level(parse_log_level(args.get("log-level")));

  if (args.given("merge")) return merge(args);
  const std::string sim_path = args.get("sim-config");
  const std::string vins_path = args.get("vins-config");
  const std::string target_path = args.get("target-config");
  const eval::MonteCarloArgs mca = eval::read_monte_carlo_args(args);
  const eval::EvaluationSetup setup = eval::load_evaluation_setup(sim_path, vins_path, mca.duration_s);
  for (const std::string& m : setup.model_mismatches) log_warn("estimator model differs from the simulator: ", m);
  const sim::SimConfig& sim_cfg = setup.sim;
  const estimator::VioOptions& options = setup.vio;
  target::TargetFilterOptions base_filter = eval::target_filter_options(Config::load_file(target_path));
  if (args.given("target-init")) {
    try {
      base_filter.init_mode = target::parse_init_mode(args.get("target-init"));
    } catch (const std::invalid_argument& e) {
      throw ArgError(std::string("--target-init: ") + e.what());
    }
  }

  eval::TargetSweepOptions o;
  o.sigmas.clear();
  for (const std::string& s : split(args.get("sigmas"))) {
    double v = 0.0;
    try {
      std::size_t used = 0;
      v = std::stod(s, &used);
      if (used != s.size()) throw std::invalid_argument(s);
    } catch (const std::exception&) {
      throw ArgError("--sigmas: not a number: '" + s + "'");
    }
    if (!(v > 0.0)) throw ArgError("--sigmas: values must be > 0, got " + s);
    o.sigmas.push_back(v);
  }
  o.modes.clear();
  for (const std::string& s : split(args.get("modes"))) {
    if (s != "ekf" && s != "skf" && s != "adaptive") {
      throw ArgError("--modes: expected ekf, skf and/or adaptive, got '" + s + "'");
    }
    o.modes.push_back(target::parse_target_mode(s));
  }
  o.representations.clear();
  for (const std::string& s : split(args.get("representations"))) {
    try {
      o.representations.push_back(target::parse_target_representation(s));
    } catch (const std::invalid_argument& e) {
      throw ArgError(std::string("--representations: ") + e.what());
    }
  }
  o.vio_only = !args.flag("no-vio-only");
  o.runs = mca.runs;
  o.first_seed = mca.first_seed;
  o.threads = mca.threads;
  o.fixed_perturb_seed = mca.perturb_seed;
  o.pixels = mca.pixels;
  o.box_chain = mca.box_chain;
  const std::size_t n_cells =
      (o.vio_only ? 1 : 0) + o.sigmas.size() * o.modes.size() * o.representations.size();
  if (n_cells == 0) throw ArgError("nothing to run (empty --sigmas/--modes/--representations and --no-vio-only)");
  const std::string out_dir = args.get("out");
  if (!out_dir.empty()) std::filesystem::create_directories(out_dir);
  if (args.flag("errors") && out_dir.empty()) throw ArgError("--errors needs --out DIR");
  o.keep_samples = args.flag("errors");

  std::fprintf(stderr, "vimot-target-eval: %zu cells x %d runs on %d threads (%s, %s, %s)\n", n_cells, o.runs,
               o.threads, sim_path.c_str(), vins_path.c_str(), target_path.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  eval::ProgressBar bar(!args.flag("quiet"));
  const std::vector<eval::TargetCell> cells = eval::run_target_sweep(
      sim_cfg, options, base_filter, o, [&bar](const eval::MonteCarloProgress& p) { bar.update(p); },
      input_guard_options_from_config(Config::load_file(vins_path)));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  const eval::MachineInfo machine = eval::machine_info();
  std::cout << eval::target_tables(cells);
  std::cout << "\n" << o.runs << " runs per cell, " << n_cells << " cells; wall time " << eval::hms(wall) << " on "
            << o.threads << " threads (" << eval::hms(wall * o.threads / static_cast<double>(n_cells * o.runs))
            << " per run and thread); machine: " << machine.nproc << " CPUs, " << machine.cpu_model << "\n";
  std::cout << "target start: " << target::to_string(base_filter.init_mode) << "; frames "
            << (o.pixels ? "from pixels (" + args.get("pixels") +
                            (o.box_chain ? ", target box from the segmenter and mask filter)" : ", true target box)") : std::string("simulated features"))
            << "\n";
  if (n_cells * static_cast<std::size_t>(o.runs) > 12) {
    std::cout << "  (each run's target tracking and target frame transform: summary.json, per_run)\n";
  } else {
    for (const auto& c : cells) {
      if (c.vio_only) continue;
      for (const auto& r : c.runs) {
        const double n = static_cast<double>(std::max<int64_t>(1, r.imu.count));
        std::printf("  %s %s σ_t %g seed %llu: target estimate on %lld of %lld frames (%.1f %%, started after %.2f s), "
                    "target features on %.1f %%, target updates on %.1f %%, longest gap without target features "
                    "%lld frames, max target-in-IMU position error %.3f m\n",
                    target::to_string(c.filter.mode), target::to_string(c.filter.representation), c.filter.sigma_t,
                    static_cast<unsigned long long>(r.sim_seed), static_cast<long long>(r.target_in_imu.count),
                    static_cast<long long>(r.imu.count), 100.0 * static_cast<double>(r.target_in_imu.count) / n,
                    r.target_init_s, 100.0 * static_cast<double>(r.frames_with_target_obs) / n,
                    100.0 * static_cast<double>(r.frames_with_target_update) / n,
                    static_cast<long long>(r.longest_gap_frames), r.target_max_error_m);
        if (base_filter.init_mode == target::TargetInitMode::kFeatures) {
          std::cout << "    filter's target frame in the true one"
                    << (r.target_stats.target_restarts > 0 ? " (after its restart) " : " ") << r.target_frame.describe()
                    << "\n";
        }
      }
    }
  }
  int diverged = 0;
  for (const auto& c : cells)
    for (const auto& r : c.runs) diverged += r.diverged ? 1 : 0;
  if (diverged > 0) std::cout << diverged << " run(s) diverged (left out of the averages; see summary.json)\n";
  if (!out_dir.empty()) {
    eval::write_text_file(out_dir + "/summary.json",
                          eval::target_summary_json(cells, sim_path, vins_path, target_path, o, wall));
    eval::write_text_file(out_dir + "/summary.csv", eval::target_summary_csv(cells));
    std::cout << "wrote " << out_dir << "/{summary.json, summary.csv}\n";
    if (o.keep_samples) {
      std::filesystem::create_directories(out_dir + "/errors");
      for (const eval::TargetCell& c : cells) {
        if (c.vio_only) continue;
        char cell_name[64];
        std::snprintf(cell_name, sizeof(cell_name), "%s_%s_%g", target::to_string(c.filter.mode),
                      target::to_string(c.filter.representation), c.filter.sigma_t);
        for (const eval::TargetRunResult& r : c.runs) {
          char prefix[128];
          std::snprintf(prefix, sizeof(prefix), "%s/errors/%s_seed%03llu_target_in_", out_dir.c_str(), cell_name,
                        static_cast<unsigned long long>(r.sim_seed));
          eval::write_errors_csv(std::string(prefix) + "imu.csv", r.target_in_imu_samples);
          eval::write_errors_csv(std::string(prefix) + "world.csv", r.target_in_world_samples);
        }
      }
      std::cout << "wrote " << out_dir << "/errors/*.csv\n";
    }
  }
  return diverged > 0 ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-target-eval", argc, argv, run); }

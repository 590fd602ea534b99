// vimot-scale-eval: the monocular metric-scale pipeline of the scale paper
// (VIO -> object tracker -> correlation scale estimator) on the simulator,
// offline (no LCM), with the configs of the LCM processes. Run i uses
// simulator seed first_seed + i. Prints per run and on average the scale
// error and the metric object pose error in the world, as the paper
// reports its trials (std per axis in m, yaw/pitch/roll std in rad), and
// the same errors of the object motion filter's states with their NEES.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <string>
#include <thread>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/eval/evaluation_setup.h"
#include "common/eval/json.h"
#include "common/eval/machine.h"
#include "common/eval/progress.h"
#include "common/eval/sim_runner.h"
#include "common/eval/writers.h"
#include "common/process/arg_parser.h"
#include "common/process/logger.h"
#include "procs/eval/monte_carlo_args.h"
#include "procs/eval/scale_run.h"

namespace {

using namespace vimot;

// One row per metric pose; the filtered columns stay empty where the
// object filter published no state (gated pose).
void write_metric_csv(const std::string& path, const eval::ScaleRunResult& r) {
  std::ofstream f(path);
  if (!f) throw std::runtime_error("cannot write '" + path + "'");
  f << "t,scale,scale_true,err_px,err_py,err_pz,err_yaw,err_pitch,err_roll,"
       "filt_err_px,filt_err_py,filt_err_pz,filt_err_yaw,filt_err_pitch,filt_err_roll,filt_nees_p,filt_nees_theta\n";
  std::map<int64_t, const eval::FilteredPoseSample*> filtered;
  for (const auto& s : r.figures.filtered_poses) filtered[s.error.utime] = &s;
  for (const auto& m : r.figures.metric_poses) {
    f << eval::utime_to_seconds_string(m.utime) << ',' << m.scale << ',' << m.scale_true;
    for (int i = 0; i < 3; ++i) f << ',' << m.err_p(i);
    for (int i = 0; i < 3; ++i) f << ',' << m.err_ypr(i);
    const auto it = filtered.find(m.utime);
    if (it == filtered.end()) {
      f << ",,,,,,,,";
    } else {
      const eval::FilteredPoseSample& s = *it->second;
      for (int i = 0; i < 3; ++i) f << ',' << s.error.err_p(i);
      for (int i = 0; i < 3; ++i) f << ',' << s.error.err_ypr(i);
      f << ',' << s.nees_p << ',' << s.nees_theta;
    }
    f << '\n';
  }
  if (!f) throw std::runtime_error("write error on '" + path + "'");
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-scale-eval",
                 "Monte-Carlo evaluation of the monocular metric-scale pipeline (scale paper): VIO\n"
                 "(mono), the object tracker (region bundle adjustment) and the correlation scale\n"
                 "estimator with its observability check, on the simulator, offline (no LCM), with\n"
                 "the configs of the LCM processes. Per run and on average: tracker valid frames,\n"
                 "scale estimates and accepted ones, scale error (median / max of the accepted,\n"
                 "and the held scale at the end), metric object pose error in the world (std per\n"
                 "axis in m, yaw/pitch/roll std in rad, as the paper's Table II), the same of the\n"
                 "object motion filter's states (OBJECT_STATE) with their NEES, VIO RMSE.\n"
                 "Exit status: 0, 2 if a run diverged or never accepted a scale, 1 on bad input.");
  args.add_option("sim-config", "FILE", "simulator scenario (mono with a target)", "config/sim_mono.yaml");
  args.add_option("vins-config", "FILE", "estimator config", "config/vins_mono.yaml");
  args.add_option("tracker-config", "FILE", "object tracker config", "config/object_tracker.yaml");
  args.add_option("scale-config", "FILE", "scale estimator config", "config/scale_estimator.yaml");
  eval::add_monte_carlo_args(args, "Monte-Carlo runs", "3");
  args.add_option("out", "DIR", "write summary.json and per-run seedNNN_metric_pose.csv");
  args.add_flag("quiet", "no progress bar");
  args.add_option("log-level", "LEVEL", "debug|info|warn|error", "warn");
  if (!args.parse(argc, argv)) return 0;
  set_log_name("scale-eval");
  set_log_level(parse_log_level(args.get("log-level")));

  const eval::MonteCarloArgs mca = eval::read_monte_carlo_args(args);
  const eval::EvaluationSetup setup =
      eval::load_evaluation_setup(args.get("sim-config"), args.get("vins-config"), mca.duration_s);
  for (const std::string& m : setup.model_mismatches) log_warn("estimator model differs from the simulator: ", m);
  eval::ScaleEvalOptions options;
  options.vio = setup.vio;
  options.tracker = object_tracker_options_from_config(Config::load_file(args.get("tracker-config")));
  options.node = scale_node_options_from_config(Config::load_file(args.get("scale-config")));
  options.pixels = mca.pixels;
  options.box_chain = mca.box_chain;

  const long long runs = mca.runs;
  const long long first = static_cast<long long>(mca.first_seed);
  const std::optional<uint64_t>& fixed_perturb = mca.perturb_seed;
  const int n_threads = std::min(mca.threads, mca.runs);
  const std::string out_dir = args.get("out");
  if (!out_dir.empty()) std::filesystem::create_directories(out_dir);

  std::fprintf(stderr, "vimot-scale-eval: %lld runs from seed %lld on %d threads (%s)\n", runs, first, n_threads,
               args.get("sim-config").c_str());
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<eval::ScaleRunResult> results(static_cast<std::size_t>(runs));
  eval::ProgressBar bar(!args.flag("quiet"));
  eval::run_parallel(
      static_cast<int>(runs), n_threads,
      [&](int i, const std::function<void(double)>& fr) {
        sim::SimConfig cfg = setup.sim;
        cfg.seed = static_cast<uint64_t>(first + i);
        results[static_cast<std::size_t>(i)] =
            eval::run_scale_on_sim(cfg, options, fixed_perturb.value_or(estimator::perturb_seed_for_run(cfg.seed)), fr);
      },
      [&bar](const eval::MonteCarloProgress& p) { bar.update(p); });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::printf("%-5s %9s %6s %9s %9s %21s %24s %24s %9s %8s %24s %24s %11s %9s\n", "seed", "valid", "tracks",
              "estimates", "accepted", "scale err med/max/end", "pos err std x/y/z [m]", "ypr err std [rad]",
              "VIO [m]", "BA ms", "filtered pos std [m]", "filtered ypr std [rad]", "NEES p/th", "filt us");
  int status = 0;
  Eigen::Vector3d sum_pstd = Eigen::Vector3d::Zero(), sum_ostd = Eigen::Vector3d::Zero();
  Eigen::Vector3d sum_fpstd = Eigen::Vector3d::Zero(), sum_fostd = Eigen::Vector3d::Zero();
  double sum_nees_p = 0.0, sum_nees_theta = 0.0;
  double sum_med = 0.0, sum_end = 0.0;
  int with_scale = 0;
  for (const eval::ScaleRunResult& r : results) {
    const eval::ScaleFigures& f = r.figures;
    const eval::AbsStats s = eval::abs_stats(f.accepted_scale_errors);
    std::printf("%-5llu %8.1f%% %6lld %9lld %9lld   %5.2f/%5.2f/%6.2f %%   %7.4f %7.4f %7.4f   %7.4f %7.4f %7.4f %9.4f "
                "%8.2f   %7.4f %7.4f %7.4f   %7.4f %7.4f %7.4f %5.1f/%5.1f %9.1f\n",
                static_cast<unsigned long long>(r.sim_seed),
                100.0 * static_cast<double>(r.tracker_valid_frames) / static_cast<double>(std::max<int64_t>(1, r.frames)),
                static_cast<long long>(r.tracks.size()), static_cast<long long>(f.estimates),
                static_cast<long long>(f.accepted), 100.0 * s.median, 100.0 * s.max, 100.0 * f.final_scale_error,
                f.position_error.std(0), f.position_error.std(1), f.position_error.std(2), f.orientation_error.std(0),
                f.orientation_error.std(1), f.orientation_error.std(2), r.vio.rmse_position_m, r.tracker_ms_mean,
                f.filtered_position_error.std(0), f.filtered_position_error.std(1), f.filtered_position_error.std(2),
                f.filtered_orientation_error.std(0), f.filtered_orientation_error.std(1),
                f.filtered_orientation_error.std(2), f.filtered_nees_position, f.filtered_nees_orientation,
                r.filter_us_mean);
    if (r.vio_diverged || f.accepted == 0) {
      status = 2;
      continue;
    }
    ++with_scale;
    sum_pstd += f.position_error.std;
    sum_ostd += f.orientation_error.std;
    sum_fpstd += f.filtered_position_error.std;
    sum_fostd += f.filtered_orientation_error.std;
    sum_nees_p += f.filtered_nees_position;
    sum_nees_theta += f.filtered_nees_orientation;
    sum_med += s.median;
    sum_end += std::abs(f.final_scale_error);
  }
  if (with_scale > 0) {
    const double n = with_scale;
    std::printf("mean over %d run(s) with a scale: scale error median %.2f %%, |held at end| %.2f %%; object position "
                "std %.4f / %.4f / %.4f m; yaw/pitch/roll std %.4f / %.4f / %.4f rad\n",
                with_scale, 100.0 * sum_med / n, 100.0 * sum_end / n, sum_pstd(0) / n, sum_pstd(1) / n,
                sum_pstd(2) / n, sum_ostd(0) / n, sum_ostd(1) / n, sum_ostd(2) / n);
    std::printf("  object motion filter: position std %.4f / %.4f / %.4f m; yaw/pitch/roll std %.4f / %.4f / %.4f rad; "
                "NEES position %.2f, orientation %.2f (3 each)\n",
                sum_fpstd(0) / n, sum_fpstd(1) / n, sum_fpstd(2) / n, sum_fostd(0) / n, sum_fostd(1) / n,
                sum_fostd(2) / n, sum_nees_p / n, sum_nees_theta / n);
  }
  std::printf("paper, trial 1 (real data): position std 0.022 / 0.031 / 0.034 m\n");
  const eval::MachineInfo machine = eval::machine_info();
  std::printf("wall time %s on %d threads; machine: %d CPUs, %s\n", eval::hms(wall).c_str(), n_threads, machine.nproc,
              machine.cpu_model.c_str());
  if (!out_dir.empty()) {
    eval::JsonWriter j;
    j.begin_object();
    j.field("tool", "vimot-scale-eval").field("sim_config", args.get("sim-config"));
    j.field("vins_config", args.get("vins-config")).field("tracker_config", args.get("tracker-config"));
    j.field("scale_config", args.get("scale-config")).field("runs", static_cast<int64_t>(runs));
    j.field("first_seed", static_cast<int64_t>(first)).field("wall_s", wall);
    j.key("per_run").begin_array();
    for (const auto& r : results) eval::write_scale_run_json(j, r);
    j.end_array();
    j.end_object();
    eval::write_text_file(out_dir + "/summary.json", j.str());
    for (const auto& r : results) {
      char name[64];
      std::snprintf(name, sizeof(name), "/seed%03llu_metric_pose.csv", static_cast<unsigned long long>(r.sim_seed));
      write_metric_csv(out_dir + name, r);
    }
    std::printf("wrote %s/{summary.json, seedNNN_metric_pose.csv}\n", out_dir.c_str());
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-scale-eval", argc, argv, run); }

// vimot-bench-vio: per-frame update time of the VIO estimator on the
// simulator (CPU ms of feed_camera on the calling thread: mean, p95, max)
// against (a) static features per camera, (b) the number of clones and
// (c) the number of SLAM features. Runs on the paper scenario's motion with
// the trajectory scenario's feature model (no fixed map: points spawned at
// 5–7 m depth whenever a camera sees fewer than keep_per_camera, as
// OpenVINS's simulator does), so it needs no shared data. Start at the
// truth, one run per setting, one thread; prints the machine.
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "common/config/config.h"
#include "common/estimator/vins_config.h"
#include "common/eval/machine.h"
#include "common/eval/sim_runner.h"
#include "common/process/arg_parser.h"
#include "common/sim/sim_config.h"
#include "procs/eval/vio_run.h"

namespace {

using namespace vimot;

struct Setting {
  std::string sweep;
  std::string label;
  int keep_per_camera;
  std::function<void(estimator::VioOptions&)> tweak;
};

std::string row(const Setting& s, const eval::SimRunResult& r) {
  char buf[320];
  const estimator::FrameTiming& st = r.mean_stage_ms;
  std::snprintf(buf, sizeof(buf),
                "%-9s %-14s %6.0f %7.2f %7.2f %7.2f   %5.2f %5.2f %5.2f %5.2f %5.2f  %7.4f %7.4f%s", s.sweep.c_str(),
                s.label.c_str(), r.static_obs_per_camera, r.timing.mean_ms, r.timing.p95_ms, r.timing.max_ms,
                st.propagate_ms, st.msckf_ms, st.slam_update_ms, st.slam_init_ms, st.marginalize_ms,
                r.errors.rmse_position_m, r.errors.rmse_orientation_deg, r.diverged ? "  DIVERGED" : "");
  return buf;
}

int run(int argc, const char* const* argv) {
  ArgParser args("vimot-bench-vio",
                 "Per-frame update time (CPU ms: mean, p95, max) of the VIO estimator on the simulator\n"
                 "against features per camera (50..400), clones (5..20) and SLAM features (0..100).\n"
                 "Paper-scenario motion, features spawned at 5-7 m (keep-N mode), start at the truth,\n"
                 "one run per setting on one thread. Stage columns: mean wall ms of propagation, MSCKF,\n"
                 "SLAM update, SLAM initialisation, marginalisation. RMSE for reference.");
  args.add_option("sim-config", "FILE", "scenario providing the motion and sensors", "config/sim_paper.yaml");
  args.add_option("vins-config", "FILE", "estimator config (the base of every setting)", "config/vins.yaml");
  args.add_option("duration", "SECONDS", "simulated time per setting", "60");
  args.add_option("seed", "N", "simulator seed", "1");
  args.add_option("features", "N", "features per camera for the clone and SLAM sweeps", "250");
  args.add_option("sweep", "WHICH", "all | features | clones | slam", "all");
  args.add_option("csv", "FILE", "also write the table as CSV");
  if (!args.parse(argc, argv)) return 0;

  sim::SimConfig base = sim::from_config(Config::load_file(args.get("sim-config")));
  base.duration = args.get_double("duration");
  base.seed = static_cast<uint64_t>(args.get_int("seed"));
  if (!(base.duration > 0.0)) throw ArgError("--duration must be > 0");
  // The trajectory scenario's feature model (config/sim_trajectory.yaml).
  base.map.floor_points = 0;
  base.map.wall_points = 0;
  base.target.enabled = false;
  base.camera.track_loss_probability = 0.0;
  base.camera.min_depth = 0.1;
  base.camera.max_range = 20.0;
  base.camera.max_depth = 7.0;
  base.camera.spawn_depth_min = 5.0;
  base.camera.spawn_depth_max = 7.0;
  const estimator::VioOptions options = estimator::load_vio_options(args.get("vins-config"));
  const int features = static_cast<int>(args.get_int("features"));
  const std::string which = args.get("sweep");
  if (which != "all" && which != "features" && which != "clones" && which != "slam") {
    throw ArgError("--sweep must be all, features, clones or slam, got '" + which + "'");
  }

  std::vector<Setting> settings;
  if (which == "all" || which == "features") {
    for (int n : {50, 100, 200, 300, 400}) settings.push_back({"features", "keep " + std::to_string(n), n, {}});
  }
  if (which == "all" || which == "clones") {
    for (int c : {5, 8, 11, 15, 20}) {
      settings.push_back({"clones", "clones " + std::to_string(c), features,
                          [c](estimator::VioOptions& o) { o.state.max_clones = c; }});
    }
  }
  if (which == "all" || which == "slam") {
    for (int m : {0, 25, 50, 100}) {
      settings.push_back({"slam", "max_slam " + std::to_string(m), features,
                          [m](estimator::VioOptions& o) { o.state.max_slam = m; }});
    }
  }

  const eval::MachineInfo machine = eval::machine_info();
  std::printf("vimot-bench-vio: %s motion, %.0f s, seed %llu, start at the truth; base %s; %d features/camera "
              "for the clone and SLAM sweeps\nmachine: %d CPUs, %s\n\n",
              sim::to_string(base.scenario).c_str(), base.duration, static_cast<unsigned long long>(base.seed),
              args.get("vins-config").c_str(), features, machine.nproc, machine.cpu_model.c_str());
  std::printf("%-9s %-14s %6s %7s %7s %7s   %5s %5s %5s %5s %5s  %7s %7s\n", "sweep", "setting", "feat", "mean",
              "p95", "max", "prop", "msckf", "s.upd", "s.ini", "marg", "RMSE p", "RMSE o");
  std::printf("%-9s %-14s %6s %7s %7s %7s   %29s  %7s %7s\n", "", "", "/cam", "CPU ms", "CPU ms", "CPU ms",
              "stage wall ms (mean)", "[m]", "[deg]");
  std::ofstream csv;
  if (args.given("csv")) {
    csv.open(args.get("csv"));
    if (!csv) throw std::runtime_error("cannot write '" + args.get("csv") + "'");
    csv << "sweep,setting,features_per_camera,ms_mean,ms_median,ms_p95,ms_max,propagate_ms,msckf_ms,slam_update_ms,"
           "slam_init_ms,marginalize_ms,rmse_position_m,rmse_orientation_deg,diverged\n";
  }
  for (const Setting& s : settings) {
    sim::SimConfig cfg = base;
    cfg.camera.keep_per_camera = s.keep_per_camera;
    estimator::VioOptions o = options;
    if (s.tweak) s.tweak(o);
    eval::SimRunOptions ro;
    ro.keep_samples = false;
    const eval::SimRunResult r = eval::run_vio_on_sim(cfg, o, 0, ro);
    std::printf("%s\n", row(s, r).c_str());
    std::fflush(stdout);
    if (csv.is_open()) {
      const estimator::FrameTiming& st = r.mean_stage_ms;
      csv << s.sweep << "," << s.label << "," << r.static_obs_per_camera << "," << r.timing.mean_ms << ","
          << r.timing.median_ms << "," << r.timing.p95_ms << "," << r.timing.max_ms << "," << st.propagate_ms << ","
          << st.msckf_ms << "," << st.slam_update_ms << "," << st.slam_init_ms << "," << st.marginalize_ms << ","
          << r.errors.rmse_position_m << "," << r.errors.rmse_orientation_deg << "," << (r.diverged ? 1 : 0) << "\n";
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) { return vimot::run_main("vimot-bench-vio", argc, argv, run); }

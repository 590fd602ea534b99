// run_vio_on_sim and run_monte_carlo: the samples are the published states
// after each camera update; results do not depend on the thread count; the
// summary does not depend on keeping the samples.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "common/config/config.h"
#include "common/estimator/initial_estimate.h"
#include "common/estimator/nav_state_of.h"
#include "common/estimator/vins_config.h"
#include "common/eval/json.h"
#include "common/eval/report.h"
#include "common/eval/sim_runner.h"
#include "common/sim/simulator.h"
#include "procs/eval/vio_run.h"

using namespace vimot;
using namespace vimot::eval;
using estimator::InitialEstimate;
using estimator::initial_estimate;
using estimator::load_vio_options;
using estimator::nav_state_of;
using estimator::perturb_seed_for_run;

namespace {

std::string source_path(const std::string& relative) { return std::string(VIMOT_SOURCE_DIR) + "/" + relative; }

sim::SimConfig paper(double duration) {
  sim::SimConfig c = sim::from_config(Config::load_file(source_path("config/sim_paper.yaml")));
  c.duration = duration;
  return c;
}

void check_identical(const SimRunResult& a, const SimRunResult& b) {
  CHECK(a.sim_seed == b.sim_seed);
  CHECK(a.perturb_seed == b.perturb_seed);
  REQUIRE(a.samples.size() == b.samples.size());
  for (std::size_t k = 0; k < a.samples.size(); ++k) {
    const FrameSample& x = a.samples[k];
    const FrameSample& y = b.samples[k];
    REQUIRE(x.utime == y.utime);
    REQUIRE(x.q_GtoI == y.q_GtoI);
    REQUIRE(x.p_IinG == y.p_IinG);
    REQUIRE(x.v_IinG == y.v_IinG);
    REQUIRE(x.cov_diag == y.cov_diag);
    REQUIRE(x.error.err_p == y.error.err_p);
    REQUIRE(x.error.nees_theta == y.error.nees_theta);
  }
  CHECK(a.errors.rmse_position_m == b.errors.rmse_position_m);
  CHECK(a.errors.rmse_orientation_deg == b.errors.rmse_orientation_deg);
  CHECK(a.errors.nees_position == b.errors.nees_position);
  CHECK(a.errors.nees_orientation == b.errors.nees_orientation);
  CHECK(a.totals.msckf_used == b.totals.msckf_used);
  CHECK(a.totals.slam_updated == b.totals.slam_updated);
}

}  // namespace

TEST_CASE("One run: a sample per camera frame, the published state's errors", "[eval][sim]") {
  const estimator::VioOptions o = load_vio_options(source_path("config/vins.yaml"));
  int callbacks = 0;
  SimRunOptions ro;
  double last_progress = 0.0;
  ro.progress = [&](double f) {
    CHECK(f >= last_progress);
    last_progress = f;
  };
  ro.on_frame = [&](const estimator::VioEstimator& est, const FrameSample& s) {
    ++callbacks;
    const NavState x = nav_state_of(est, true);
    CHECK(x.updated);
    CHECK(x.utime == s.utime);
    CHECK(x.p_IinG == s.p_IinG);
    CHECK(x.covariance.diagonal() == s.cov_diag);
    CHECK(x.num_clones >= 1);
    CHECK(s.cpu_ms >= 0.0);
  };
  const SimRunResult r = run_vio_on_sim(paper(3.0), o, 0, ro);
  CHECK(last_progress == 1.0);
  CHECK_FALSE(r.diverged);
  CHECK(r.camera_frames == 31);  // 0 .. 3 s at 10 Hz
  CHECK(r.frames_processed == 31);
  CHECK(r.frames_without_truth == 0);
  CHECK(static_cast<int>(r.samples.size()) == 31);
  CHECK(callbacks == 31);
  CHECK(r.errors.count == 31);
  CHECK(r.timing.count == 31);
  CHECK(r.samples.front().utime == 1000000);  // first frame at the start, on the initial state
  CHECK(r.samples[1].utime == 1100000);
  CHECK(r.perturb_seed == 0);
  // Started at the truth: small errors after 3 s.
  CHECK(r.errors.rmse_position_m < 0.05);
  CHECK(r.errors.rmse_orientation_deg < 0.5);
  CHECK(r.path_length_m > 3.0);
  CHECK(r.target_observations_ignored > 0);

  // Perturbed: the first sample carries the perturbation.
  const SimRunResult p = run_vio_on_sim(paper(0.5), o, 99);
  const InitialEstimate x0 = initial_estimate(sim::Simulator(paper(0.5)).initial_state(), o, 99);
  CHECK(p.samples.front().error.err_p.norm() > 0.0);
  CHECK(p.samples.front().error.err_p.norm() < 10.0 * std::sqrt(x0.P0.block<3, 3>(3, 3).trace()));
}

TEST_CASE("Monte Carlo: same results on 1 and 2 threads, and without samples", "[eval][sim]") {
  const estimator::VioOptions o = load_vio_options(source_path("config/vins.yaml"));
  MonteCarloOptions mc;
  mc.runs = 2;
  mc.first_seed = 5;
  mc.threads = 1;
  const sim::SimConfig base = paper(2.0);
  int progress_calls = 0;
  const auto one = run_monte_carlo(base, o, mc, [&](const MonteCarloProgress& p) {
    ++progress_calls;
    CHECK(p.runs_total == 2);
    CHECK(p.fraction >= 0.0);
    CHECK(p.fraction <= 1.0);
  });
  CHECK(progress_calls >= 1);
  mc.threads = 2;
  const auto two = run_monte_carlo(base, o, mc);
  REQUIRE(one.size() == 2);
  REQUIRE(two.size() == 2);
  CHECK(one[0].sim_seed == 5);
  CHECK(one[1].sim_seed == 6);
  CHECK(one[0].perturb_seed == perturb_seed_for_run(5));
  CHECK(one[0].samples.front().p_IinG != one[1].samples.front().p_IinG);  // independent perturbations
  check_identical(one[0], two[0]);
  check_identical(one[1], two[1]);

  mc.keep_samples = false;
  const auto lean = run_monte_carlo(base, o, mc);
  CHECK(lean[0].samples.empty());
  CHECK(lean[1].errors.rmse_position_m == one[1].errors.rmse_position_m);
  CHECK(lean[1].errors.nees_orientation == one[1].errors.nees_orientation);

  mc.perturb = false;
  CHECK(run_monte_carlo(base, o, mc)[0].perturb_seed == 0);
  mc.perturb = true;
  mc.fixed_perturb_seed = 77;
  mc.runs = 1;
  CHECK(run_monte_carlo(base, o, mc)[0].perturb_seed == 77);

  // The summary files describe the same runs.
  const std::string json = summary_json(one, RunContext{});
  CHECK(JsonValue::parse(json).at("summary").at("rmse_position_m").number() ==
        Approx(0.5 * (one[0].errors.rmse_position_m + one[1].errors.rmse_position_m)).epsilon(1e-12));
  const std::string csv = summary_csv(one);
  CHECK(std::count(csv.begin(), csv.end(), '\n') == 4);  // header, 2 runs, mean
  const std::string table = results_table(one);
  CHECK_THAT(table, Catch::Contains("mean"));
}

TEST_CASE("A bad configuration is refused before any thread starts", "[eval][sim]") {
  estimator::VioOptions o = load_vio_options(source_path("config/vins.yaml"));
  MonteCarloOptions mc;
  mc.runs = 0;
  CHECK_THROWS_AS(run_monte_carlo(paper(1.0), o, mc), std::invalid_argument);
  mc.runs = 1;
  sim::SimConfig bad = paper(1.0);
  bad.imu.rate_hz = -1.0;
  CHECK_THROWS_AS(run_monte_carlo(bad, o, mc), std::invalid_argument);
}

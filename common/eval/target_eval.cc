#include "common/eval/target_eval.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "common/eval/json.h"
#include "common/eval/writers.h"
#include "common/target/target_filter_config.h"

namespace vimot {
namespace eval {

using target::TargetFilterOptions;
using target::TargetRepresentation;
using target::TargetUpdateMode;

target::TargetFilterOptions target_filter_options(const Config& config) {
  const target::TargetSection t = target::target_section_from_config(config);
  if (!t.enabled) config.fail("target.mode", "none attaches no filter: not a target-filter evaluation");
  return t.filter;
}

TargetCellSummary summarize(const TargetCell& cell) {
  TargetCellSummary s;
  std::vector<ErrorSummary> ti, tg, imu;
  for (const TargetRunResult& r : cell.runs) {
    ++s.runs;
    if (r.diverged) {
      ++s.diverged;
      continue;
    }
    ti.push_back(r.target_in_imu);
    tg.push_back(r.target_in_world);
    imu.push_back(r.imu);
  }
  s.target_in_imu = aggregate(ti);
  s.target_in_world = aggregate(tg);
  s.imu = aggregate(imu);
  return s;
}

namespace {

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), f, v);
  return buf;
}

// "m / deg" of a MonteCarloSummary, 5 significant-ish digits like the paper.
std::string md(const MonteCarloSummary& s) {
  if (s.runs == 0) return "×";
  const double p = s.rmse_position_m.mean;
  return fmt(p < 0.1 ? "%.5f" : "%.3f", p) + " / " + fmt("%.3f", s.rmse_orientation_deg.mean);
}

std::string nees(const MonteCarloSummary& s) {
  if (s.runs == 0) return "×";
  return fmt("%.2f", s.nees_position.mean) + " / " + fmt("%.2f", s.nees_orientation.mean);
}

std::string div_note(const TargetCellSummary& s) {
  if (s.diverged == 0 || s.diverged == s.runs) return "";
  return " (" + std::to_string(s.diverged) + " div)";
}

const TargetCell* find_cell(const std::vector<TargetCell>& cells, TargetUpdateMode m, TargetRepresentation rep,
                            double sigma) {
  for (const TargetCell& c : cells) {
    if (!c.vio_only && c.filter.mode == m && c.filter.representation == rep && c.filter.sigma_t == sigma) return &c;
  }
  return nullptr;
}

std::vector<double> sigmas_of(const std::vector<TargetCell>& cells) {
  std::vector<double> s;
  for (const TargetCell& c : cells) {
    if (!c.vio_only && std::find(s.begin(), s.end(), c.filter.sigma_t) == s.end()) s.push_back(c.filter.sigma_t);
  }
  std::sort(s.begin(), s.end());
  return s;
}

std::string sigma_str(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", s);
  return buf;
}

}  // namespace

std::string target_tables(const std::vector<TargetCell>& cells) {
  std::ostringstream out;
  const std::vector<double> sigmas = sigmas_of(cells);
  const TargetRepresentation reps[] = {TargetRepresentation::kGlobal, TargetRepresentation::kLocal};
  const struct {
    TargetUpdateMode mode;
    const char* title;
  } tables[] = {{TargetUpdateMode::kEkf, "Table I (EKF, tightly coupled)"}, {TargetUpdateMode::kSkf, "Table II (SKF)"},
                {TargetUpdateMode::kAdaptive, "Adaptive (σ_t = the start of the estimate)"}};
  for (const auto& t : tables) {
    bool any = false;
    for (double s : sigmas)
      for (auto rep : reps) any = any || find_cell(cells, t.mode, rep, s);
    if (!any) continue;
    out << t.title << ": average RMSE m / deg\n\n";
    out << "| σ_t | T in I (G) | T in G (G) | I in G (G) | T in I (L) | T in G (L) | I in G (L) |\n";
    out << "| --- | --- | --- | --- | --- | --- | --- |\n";
    for (double s : sigmas) {
      out << "| " << sigma_str(s);
      for (auto rep : reps) {
        const TargetCell* c = find_cell(cells, t.mode, rep, s);
        if (!c) {
          out << " | – | – | –";
          continue;
        }
        const TargetCellSummary cs = summarize(*c);
        out << " | " << md(cs.target_in_imu) << div_note(cs) << " | " << md(cs.target_in_world) << " | "
            << md(cs.imu);
      }
      out << " |\n";
    }
    out << "\n";
  }
  for (const TargetCell& c : cells) {
    if (!c.vio_only) continue;
    const TargetCellSummary cs = summarize(c);
    out << "VIO only (no target in the state): IMU in G " << md(cs.imu) << div_note(cs) << ", NEES pos / ori "
        << nees(cs.imu) << " (" << cs.runs << " runs)\n\n";
  }
  out << "Average NEES position / orientation (ideal 3)\n\n";
  out << "| σ_t | mode | T in I (G) | T in G (G) | I in G (G) | T in I (L) | T in G (L) | I in G (L) |\n";
  out << "| --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const auto& t : tables) {
    for (double s : sigmas) {
      bool any = false;
      for (auto rep : reps) any = any || find_cell(cells, t.mode, rep, s);
      if (!any) continue;
      out << "| " << sigma_str(s) << " | " << target::to_string(t.mode);
      for (auto rep : reps) {
        const TargetCell* c = find_cell(cells, t.mode, rep, s);
        if (!c) {
          out << " | – | – | –";
          continue;
        }
        const TargetCellSummary cs = summarize(*c);
        out << " | " << nees(cs.target_in_imu) << " | " << nees(cs.target_in_world) << " | " << nees(cs.imu);
      }
      out << " |\n";
    }
  }
  return out.str();
}

namespace {

void write_mc(JsonWriter& j, const std::string& key, const MonteCarloSummary& s) {
  j.key(key).begin_object();
  j.field("rmse_position_m", s.rmse_position_m.mean).field("rmse_position_m_std", s.rmse_position_m.std);
  j.field("rmse_orientation_deg", s.rmse_orientation_deg.mean)
      .field("rmse_orientation_deg_std", s.rmse_orientation_deg.std);
  j.field("nees_position", s.nees_position.mean).field("nees_orientation", s.nees_orientation.mean);
  j.field("runs", s.runs).field("samples", s.samples);
  j.end_object();
}

std::string cell_mode(const TargetCell& c) { return c.vio_only ? "vio" : target::to_string(c.filter.mode); }
std::string cell_rep(const TargetCell& c) { return c.vio_only ? "-" : target::to_string(c.filter.representation); }

}  // namespace

std::string target_summary_json(const std::vector<TargetCell>& cells, const std::string& sim_config,
                                const std::string& vins_config, const std::string& target_config,
                                const TargetSweepOptions& o, double wall_s) {
  JsonWriter j;
  j.begin_object();
  j.field("tool", "vimot-target-eval").field("sim_config", sim_config).field("vins_config", vins_config);
  j.field("target_config", target_config).field("runs", o.runs).field("first_seed", o.first_seed);
  j.field("threads", o.threads).field("wall_s", wall_s).field("from_pixels", o.pixels.has_value())
      .field("box_from_segmenter", o.box_chain.has_value());
  j.key("cells").begin_array();
  for (const TargetCell& c : cells) {
    const TargetCellSummary s = summarize(c);
    j.begin_object();
    j.field("mode", cell_mode(c)).field("representation", cell_rep(c));
    if (c.vio_only) {
      j.key("sigma_t").null();
    } else {
      j.field("sigma_t", c.filter.sigma_t);
    }
    j.field("runs", s.runs).field("diverged", s.diverged);
    write_mc(j, "target_in_imu", s.target_in_imu);
    write_mc(j, "target_in_world", s.target_in_world);
    write_mc(j, "imu", s.imu);
    j.key("per_run").begin_array();
    for (const TargetRunResult& r : c.runs) {
      j.begin_object();
      j.field("sim_seed", r.sim_seed).field("perturb_seed", r.perturb_seed).field("diverged", r.diverged);
      if (r.diverged) j.field("divergence_reason", r.divergence_reason);
      if (!c.vio_only) {
        j.key("target_frame").begin_object();
        j.field("angle_deg", r.target_frame.angle_deg());
        j.key("q_TtoTest").begin_array();
        for (int k = 0; k < 4; ++k) j.value(r.target_frame.q_TtoTest(k));
        j.end_array();
        j.key("p_TestInT").begin_array();
        for (int k = 0; k < 3; ++k) j.value(r.target_frame.p_TestInT(k));
        j.end_array();
        j.end_object();
        j.key("tracking").begin_object();
        j.field("frames_evaluated", r.imu.count).field("frames_with_target", r.target_in_imu.count);
        j.field("frames_with_target_obs", r.frames_with_target_obs);
        j.field("frames_with_target_update", r.frames_with_target_update);
        j.field("longest_gap_frames", r.longest_gap_frames).field("target_max_error_m", r.target_max_error_m);
        j.field("target_init_s", r.target_init_s).field("cpu_ms_per_frame", r.cpu_ms_per_frame);
        j.end_object();
        const target::TargetUpdateStats& ts = r.target_stats;
        j.key("target_updates").begin_object();
        j.field("obs_received", ts.obs_received).field("obs_used", ts.obs_used);
        j.field("tracks_used", ts.tracks_used).field("rejected_short", ts.rejected_short);
        j.field("rejected_triangulation", ts.rejected_triangulation).field("rejected_chi2", ts.rejected_chi2);
        j.field("points_initialized", ts.points_initialized).field("points_rejected_init", ts.points_rejected_init);
        j.field("point_updates", ts.point_updates).field("points_rejected_chi2", ts.points_rejected_chi2);
        if (ts.adaptive_frames > 0) {
          j.field("adaptive_frames", ts.adaptive_frames).field("adaptive_coupled_frames", ts.adaptive_coupled_frames);
          j.field("adaptive_violations", ts.adaptive_violations);
          j.field("adaptive_sigma_mean", ts.adaptive_sigma_sum / static_cast<double>(ts.adaptive_frames));
          j.field("adaptive_sigma_last", ts.adaptive_sigma_last);
          j.field("target_restarts", ts.target_restarts);
        }
        j.end_object();
      }
      j.key("target_in_imu");
      write_summary_json(j, r.target_in_imu);
      j.key("target_in_world");
      write_summary_json(j, r.target_in_world);
      j.key("imu");
      write_summary_json(j, r.imu);
      j.field("wall_s", r.wall_s);
      j.end_object();
    }
    j.end_array();
    j.end_object();
  }
  j.end_array();
  j.end_object();
  return j.str();
}

std::vector<TargetCell> read_target_cells(const std::string& summary_json) {
  try {
    const JsonValue doc = JsonValue::parse(read_text_file(summary_json));
    const JsonValue& cells = doc.at("cells");
    std::vector<TargetCell> out;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const JsonValue& c = cells.at(i);
      TargetCell cell;
      cell.vio_only = c.at("mode").string() == "vio";
      if (!cell.vio_only) {
        cell.filter.mode = target::parse_target_mode(c.at("mode").string());
        cell.filter.representation = target::parse_target_representation(c.at("representation").string());
        cell.filter.sigma_t = c.at("sigma_t").number();
      }
      const JsonValue& runs = c.at("per_run");
      for (std::size_t k = 0; k < runs.size(); ++k) {
        const JsonValue& r = runs.at(k);
        TargetRunResult run;
        run.sim_seed = static_cast<uint64_t>(r.at("sim_seed").number());
        run.perturb_seed = static_cast<uint64_t>(r.at("perturb_seed").number());
        run.diverged = r.at("diverged").boolean();
        if (run.diverged && r.has("divergence_reason")) run.divergence_reason = r.at("divergence_reason").string();
        run.target_in_imu = summary_from_json(r.at("target_in_imu"));
        run.target_in_world = summary_from_json(r.at("target_in_world"));
        run.imu = summary_from_json(r.at("imu"));
        run.wall_s = r.at("wall_s").number();
        if (r.has("tracking")) {  // (files written before it was added have none)
          const JsonValue& t = r.at("tracking");
          run.frames_with_target_obs = static_cast<int64_t>(t.at("frames_with_target_obs").number());
          run.frames_with_target_update = static_cast<int64_t>(t.at("frames_with_target_update").number());
          run.longest_gap_frames = static_cast<int64_t>(t.at("longest_gap_frames").number());
          run.target_max_error_m = t.at("target_max_error_m").number();
          run.target_init_s = t.at("target_init_s").number();
        }
        cell.runs.push_back(run);
      }
      out.push_back(std::move(cell));
    }
    return out;
  } catch (const std::exception& e) {
    throw std::runtime_error("'" + summary_json + "': " + e.what());
  }
}

std::string target_summary_csv(const std::vector<TargetCell>& cells) {
  std::ostringstream out;
  out << "mode,representation,sigma_t,run,diverged,"
         "ti_rmse_p_m,ti_rmse_r_deg,ti_nees_p,ti_nees_r,"
         "tg_rmse_p_m,tg_rmse_r_deg,tg_nees_p,tg_nees_r,"
         "imu_rmse_p_m,imu_rmse_r_deg,imu_nees_p,imu_nees_r\n";
  auto row = [&out](const ErrorSummary& a, const ErrorSummary& b, const ErrorSummary& c) {
    for (const ErrorSummary* s : {&a, &b, &c}) {
      out << ',' << fmt("%.9g", s->rmse_position_m) << ',' << fmt("%.9g", s->rmse_orientation_deg) << ','
          << fmt("%.9g", s->nees_position) << ',' << fmt("%.9g", s->nees_orientation);
    }
    out << '\n';
  };
  auto mean_of = [](const MonteCarloSummary& m) {
    ErrorSummary s;
    s.rmse_position_m = m.rmse_position_m.mean;
    s.rmse_orientation_deg = m.rmse_orientation_deg.mean;
    s.nees_position = m.nees_position.mean;
    s.nees_orientation = m.nees_orientation.mean;
    return s;
  };
  for (const TargetCell& c : cells) {
    const std::string head = cell_mode(c) + "," + cell_rep(c) + "," + (c.vio_only ? "" : sigma_str(c.filter.sigma_t));
    for (const TargetRunResult& r : c.runs) {
      out << head << ',' << r.sim_seed << ',' << (r.diverged ? 1 : 0);
      row(r.target_in_imu, r.target_in_world, r.imu);
    }
    const TargetCellSummary s = summarize(c);
    out << head << ",mean," << s.diverged;
    row(mean_of(s.target_in_imu), mean_of(s.target_in_world), mean_of(s.imu));
  }
  return out.str();
}

}  // namespace eval
}  // namespace vimot

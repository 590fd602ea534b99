#include "common/eval/progress.h"

#include <unistd.h>

#include <cstdio>

namespace vimot {
namespace eval {

std::string hms(double s) {
  const long t = static_cast<long>(s + 0.5);
  char buf[32];
  if (t >= 3600) {
    std::snprintf(buf, sizeof(buf), "%ldh%02ldm%02lds", t / 3600, (t / 60) % 60, t % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%ldm%02lds", t / 60, t % 60);
  }
  return buf;
}

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled), tty_(isatty(STDERR_FILENO) == 1) {}

void ProgressBar::update(const MonteCarloProgress& p) {
  if (!enabled_) return;
  const double eta = p.fraction > 1e-6 ? p.elapsed_s * (1.0 - p.fraction) / p.fraction : 0.0;
  char line[160];
  if (tty_) {
    const int width = 30;
    const int filled = static_cast<int>(p.fraction * width + 0.5);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(width, '.');
    std::snprintf(line, sizeof(line), "\r[%s] %3.0f%%  runs %d/%d  elapsed %s  ETA %s   ", bar.c_str(),
                  100.0 * p.fraction, p.runs_done, p.runs_total, hms(p.elapsed_s).c_str(),
                  p.fraction > 1e-6 ? hms(eta).c_str() : "--");
    std::fputs(line, stderr);
    if (p.runs_done == p.runs_total) std::fputs("\n", stderr);
  } else if (p.runs_done != last_done_) {
    std::snprintf(line, sizeof(line), "runs %d/%d  elapsed %s  ETA %s\n", p.runs_done, p.runs_total,
                  hms(p.elapsed_s).c_str(), hms(eta).c_str());
    std::fputs(line, stderr);
  }
  last_done_ = p.runs_done;
  std::fflush(stderr);
}

}  // namespace eval
}  // namespace vimot

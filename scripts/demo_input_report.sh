#!/usr/bin/env bash
# Per process and input channel of a demo run: what its publishers sent,
# what the process received ("in"), and what its heartbeat counted as lost
# (from the sheriff's output: the simulator's "done:" line, and each
# process's "stopping:" line, common/process/process.h, which also gives
# what it published, "out <channel>"). Every process stopped with input
# still queued drains it or counts it as lost, so per channel
#   published = received + counted lost
# exactly, unless the network itself lost messages at the very end. This
# covers the logger (vimot-logger counts what it logged per channel); with
# the run's LCM log also what the log holds against what the logger says.
# Channels with no counted publisher (HEARTBEAT) are left out; a channel's
# publishers add up (the rendering simulator says "0 on FEATURES", which the
# feature tracker publishes).
#   scripts/demo_input_report.sh SHERIFF_OUTPUT [LCM_LOG]
# Exits 1 naming each channel whose count is not exact ("NOT COUNTED"),
# each process that left no "stopping:" line (killed: "NO FINAL COUNT") and
# each channel whose log holds other than what the logger received
# ("LOG DIFFERS").
set -euo pipefail
if [ $# -lt 1 ] || [ $# -gt 2 ] || [ "$1" = -h ] || [ "$1" = --help ]; then
  awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"
  [ $# -eq 1 ] && exit 0 || exit 1
fi
[ -r "$1" ] || { echo "demo_input_report.sh: cannot read '$1'" >&2; exit 1; }
logged=$(mktemp)
trap 'rm -f "$logged"' EXIT
if [ $# -eq 2 ]; then
  bin="${VIMOT_BIN:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/build/bin}"
  "$bin/vimot-log-summary" "$2" > "$logged"
fi
awk '
  FILENAME == ARGV[1] { if ($2 ~ /^vimot\./) logged[$1] = $3; next }
  function items(text, out,   n, parts, i) { n = split(text, parts, ", "); for (i = 1; i <= n; ++i) out[i] = parts[i]; return n }
  function proc_name(   name) { name = $1; gsub(/[][]/, "", name); return name }
  /\[sim\].*INFO: (done|stopped early): / {
    text = $0; sub(/.*INFO: (done|stopped early): /, "", text)
    n = items(text, it)
    for (i = 1; i <= n; ++i) { split(it[i], w, " "); if (w[2] == "on") { published[w[3]] = w[1] } }
  }
  /INFO: started \(pid/ { name = proc_name(); if (name != "sim" && !(name in started)) { started[name] = 1; order[++np] = name } }
  /INFO: stopping: in / {
    name = proc_name(); stopped[name] = 1
    text = $0; sub(/.*INFO: stopping: /, "", text)
    n = items(text, it)
    for (i = 1; i <= n; ++i) {
      k = split(it[i], w, " ")
      if (k == 3 && (w[1] == "in" || w[1] == "lost" || w[1] == "out")) count[name, w[1], w[2]] = w[3]
      if (k == 3 && w[1] == "in" && !((name, w[2]) in has_in)) { has_in[name, w[2]] = 1; ins[name] = ins[name] " " w[2] }
      if (k == 3 && w[1] == "out") out_total[w[2]] += w[3]
      if (k == 2 && (w[1] == "dropped" || w[1] == "lost" || w[1] == "errors")) count[name, w[1]] = w[2]
    }
  }
  END {
    if (length(published) == 0) { print "no \"done:\" line of the simulator: nothing to compare"; exit 1 }
    for (ch in out_total) published[ch] += out_total[ch]
    status = 0
    for (p = 1; p <= np; ++p) {
      name = order[p]
      if (!(name in stopped)) { printf "%s: NO FINAL COUNT (no \"stopping:\" line: killed?)\n", name; status = 1; continue }
      rows = ""
      n = split(ins[name], chans, " ")
      for (i = 1; i <= n; ++i) {
        ch = chans[i]
        if (!(ch in published)) continue
        received = count[name, "in", ch]; lost = count[name, "lost", ch] + 0
        rows = rows sprintf("  %-17s published %6d  received %6d  counted lost %d", ch, published[ch], received, lost)
        if (published[ch] != received + lost) {
          rows = rows sprintf("  NOT COUNTED: %d missed", published[ch] - received - lost); status = 1
        }
        if (length(logged) > 0 && name == "logger" && logged[ch] + 0 != received) {
          rows = rows sprintf("  LOG DIFFERS: the log holds %d", logged[ch]); status = 1
        }
        rows = rows "\n"
      }
      if (rows != "") printf "%s (dropped %d, lost %d, errors %d):\n%s", name, count[name, "dropped"], count[name, "lost"], count[name, "errors"], rows
    }
    exit status
  }' "$logged" "$1"

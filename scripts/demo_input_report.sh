#!/usr/bin/env bash
# Per process and input stream of a demo run: what the simulator published,
# what the process received, and what its heartbeat counted as lost (from
# the sheriff's output: the simulator's "done:" line and each process's
# "stopping:" line, common/process/process.h). Published − received is what
# the network lost; a process that counts its input exactly says the same.
# With the run's LCM log: also what each process published against what
# the logger recorded (the logger has no heartbeat; its loss changes the
# figures evaluated from the log too).
#   scripts/demo_input_report.sh SHERIFF_OUTPUT [LCM_LOG]
# Exits 1 if some process's count differs from what it missed ("NOT COUNTED":
# e.g. input still queued, or lost at the end, when the process was stopped:
# no later message shows the gap).
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
  /\[sim\].*INFO: (done|stopped early): / {
    text = $0; sub(/.*INFO: (done|stopped early): /, "", text)
    n = items(text, it)
    for (i = 1; i <= n; ++i) { split(it[i], w, " "); if (w[2] == "on") { published[w[3]] = w[1]; streams[++ns] = w[3] } }
  }
  /INFO: stopping: in / {
    name = $1; gsub(/[][]/, "", name)
    text = $0; sub(/.*INFO: stopping: /, "", text)
    if (!(name in seen)) { seen[name] = 1; procs[++np] = name }
    n = items(text, it)
    for (i = 1; i <= n; ++i) {
      k = split(it[i], w, " ")
      if (k == 3 && (w[1] == "in" || w[1] == "lost" || w[1] == "out")) count[name, w[1], w[2]] = w[3]
      if (k == 3 && w[1] == "out") outs[name] = outs[name] " " w[2]
      if (k == 2 && (w[1] == "dropped" || w[1] == "lost" || w[1] == "errors")) count[name, w[1]] = w[2]
    }
  }
  END {
    if (ns == 0) { print "no \"done:\" line of the simulator: nothing to compare"; exit 1 }
    status = 0
    if (length(logged) > 0) {
      printf "logger:\n"
      for (s = 1; s <= ns; ++s) printf "  %-13s published %6d  logged   %6d\n", streams[s], published[streams[s]], logged[streams[s]]
    }
    for (p = 1; p <= np; ++p) {
      name = procs[p]; rows = ""
      for (s = 1; s <= ns; ++s) {
        ch = streams[s]
        if (!((name, "in", ch) in count)) continue
        missed = published[ch] - count[name, "in", ch]; lost = count[name, "lost", ch] + 0
        rows = rows sprintf("  %-13s published %6d  received %6d  counted lost %d", ch, published[ch], count[name, "in", ch], lost)
        if (missed != lost) { rows = rows sprintf("  NOT COUNTED: %d missed", missed); status = 1 }
        rows = rows "\n"
      }
      if (length(logged) > 0) {
        n = split(outs[name], chans, " ")
        for (i = 1; i <= n; ++i) {
          rows = rows sprintf("  %-13s published %6d  logged   %6d\n", chans[i], count[name, "out", chans[i]], logged[chans[i]])
        }
      }
      if (rows != "") printf "%s (dropped %d, lost %d, errors %d):\n%s", name, count[name, "dropped"], count[name, "lost"], count[name, "errors"], rows
    }
    exit status
  }' "$logged" "$1"

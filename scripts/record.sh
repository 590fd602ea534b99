#!/usr/bin/env bash
# Records a live vimot run with vimot-logger: every channel but procman's own
# (PMD_*), i.e. sensor inputs, estimates and heartbeats (the heartbeats count
# lost input, which tells whether a replay can equal the run). Unlike
# lcm-logger it holds a long queue while the disk or the CPU is slow, counts
# what it logged per channel in its heartbeat, and when stopped logs what is
# still queued (--drain) or counts it as lost: no message is lost silently.
#
# Usage: scripts/record.sh [-o FILE] [--no-images] [-c REGEX] [--duration S] [--drain S] [--url URL]
#   -o FILE         log to write (default out/record-<date>.lcmlog; an
#                   existing file is an error, not overwritten)
#   --no-images     leave out CAM_LEFT, CAM_RIGHT and TARGET_MASK* (7 MB/s
#                   from the renderer): what the estimators and their
#                   evaluation need stays in
#   -c REGEX        record only the channels REGEX matches (whole name)
#   --duration S    stop after S seconds (default: until Ctrl-C / SIGINT /
#                   SIGTERM, e.g. a sheriff's stop signal)
#   --drain S       when stopped, go on logging for at most S seconds until
#                   the network has been quiet for 0.5 s (default 3; keep it
#                   below a sheriff's stop_time_allowed)
#   --url URL       LCM network (default $LCM_DEFAULT_URL, else LCM's)
# Runs $VIMOT_BIN/vimot-logger (default: $VIMOT_BUILD_DIR/bin, else the
# repository's build/bin).
#
# The log's event times are the logger's wall clock, the messages' utimes
# sensor time: a run at 2x real time is a log "recorded at 2x", which
# vimot-log-summary prints and scripts/replay.sh corrects for.
# Replay: scripts/replay.sh FILE (docs/record_replay.md).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

out="$here/out/record-$(date +%Y%m%d-%H%M%S).lcmlog"
regex=""
invert=1
exclude='PMD_.*'
duration=""
drain=3
url="${LCM_DEFAULT_URL:-}"
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    -o) out="${2:?record.sh: -o needs a file}"; shift 2 ;;
    --no-images) exclude='PMD_.*|CAM_LEFT|CAM_RIGHT|TARGET_MASK.*'; shift ;;
    -c) regex="${2:?record.sh: -c needs a regular expression}"; invert=0; shift 2 ;;
    --duration) duration="${2:?record.sh: --duration needs seconds}"; shift 2 ;;
    --drain) drain="${2:?record.sh: --drain needs seconds}"; shift 2 ;;
    --url) url="${2:?record.sh: --url needs a URL}"; shift 2 ;;
    *) echo "record.sh: unknown argument '$1' (see --help)" >&2; exit 1 ;;
  esac
done
for value in "$duration" "$drain"; do
  if [ -n "$value" ] && ! [[ "$value" =~ ^[0-9]+([.][0-9]+)?$ ]]; then
    echo "record.sh: --duration and --drain take a number of seconds, got '$value'" >&2
    exit 1
  fi
done
if [ -e "$out" ]; then
  echo "record.sh: $out exists; not overwriting it" >&2
  exit 1
fi
mkdir -p "$(dirname "$out")"
logger="${VIMOT_BIN:-${VIMOT_BUILD_DIR:-$here/build}/bin}/vimot-logger"
if [ ! -x "$logger" ]; then
  echo "record.sh: $logger not found: build first (scripts/build.sh) or set VIMOT_BIN" >&2
  exit 1
fi

# Both regexes match the whole channel name.
args=(--log "$out" --drain "$drain" --drain-quiet 0.5)
if [ $invert -eq 1 ]; then args+=(--exclude "$exclude"); else args+=(--channels "$regex"); fi
[ -n "$url" ] && args+=(--lcm-url "$url")
echo "record.sh: writing $out" >&2
if [ -n "$duration" ]; then
  # SIGINT: vimot-logger drains, then closes the log cleanly.
  status=0
  timeout -s INT "$duration" "$logger" "${args[@]}" || status=$?
  [ $status -eq 124 ] && status=0
  exit $status
fi
exec "$logger" "${args[@]}"

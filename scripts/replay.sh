#!/usr/bin/env bash
# Plays a recorded vimot log back, right.
#
# Usage: scripts/replay.sh LOG [--speed S] [--all | --sensors | -e REGEX] [--url URL] [--stack]
#        scripts/replay.sh LOG --offline
#   --speed S   real-time factor of the data (default 1: as fast as the
#               sensors produced it). The log may have been recorded at
#               another speed (the demo runs at 2x): its event times are the
#               logger's wall clock, so lcm-logplayer's own -s is relative to
#               that. This script reads the recorded speed (vimot-log-summary
#               --speed) and plays at S / recorded.
#   channels    what is played (default: the estimators' inputs IMU,
#               FEATURES, GROUND_TRUTH, so the vins and target_filter
#               processes you run get their input and no old estimates are
#               replayed beside theirs):
#     --sensors   the sensor drivers' outputs: IMU, CAM_LEFT, CAM_RIGHT,
#                 GROUND_TRUTH, TARGET_BOX_TRUTH, TARGET_MASK_TRUTH (for the
#                 pipeline from pixels: feature tracker and on)
#     --all       everything in the log (to watch a run in lcm-spy)
#     -e REGEX    lcm-logplayer's channel regular expression
#   --url URL   LCM network (default $LCM_DEFAULT_URL, else LCM's)
#   --stack     play into a fresh vins and target filter under vimot-sheriff
#               (sheriff_configs/log_playback.pmd: logger, vins,
#               target_filter, the player) and record their new run in
#               $VIMOT_OUT/replay.lcmlog (default out/replay-<date>/);
#               configs VIMOT_VINS_CONFIG (vins.yaml) and VIMOT_TARGET_CONFIG
#               (target_filter.yaml; for a real log vins_euroc.yaml and
#               target_filter_live.yaml)
#   --offline   no network: replay the log deterministically through the
#               vins / target_filter Nodes (vimot-log-replay, configs
#               config/$VIMOT_VINS_CONFIG and config/target_filter.yaml) and
#               compare their outputs byte for byte with the logged ones;
#               exits 3 if they differ
# The processes to replay into are started as usual, e.g.
#   build/bin/vimot-vins --config config/vins.yaml &
#   build/bin/vimot-target-filter --config config/target_filter.yaml &
# Details: docs/record_replay.md.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${VIMOT_BUILD_DIR:-$here/build}/bin"

log=""
speed=1
regex='^(IMU|FEATURES|GROUND_TRUTH)$'
url="${LCM_DEFAULT_URL:-}"
offline=0
stack=0
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    --speed) speed="${2:?replay.sh: --speed needs a factor}"; shift 2 ;;
    --sensors) regex='^(IMU|CAM_LEFT|CAM_RIGHT|GROUND_TRUTH|TARGET_BOX_TRUTH|TARGET_MASK_TRUTH)$'; shift ;;
    --all) regex='.*'; shift ;;
    -e) regex="${2:?replay.sh: -e needs a regular expression}"; shift 2 ;;
    --url) url="${2:?replay.sh: --url needs a URL}"; shift 2 ;;
    --offline) offline=1; shift ;;
    --stack) stack=1; shift ;;
    -*) echo "replay.sh: unknown option '$1' (see --help)" >&2; exit 1 ;;
    *) [ -z "$log" ] || { echo "replay.sh: one log only ('$log', '$1')" >&2; exit 1; }; log="$1"; shift ;;
  esac
done
[ -n "$log" ] || { echo "replay.sh: no log given (see --help)" >&2; exit 1; }
[ -f "$log" ] || { echo "replay.sh: no such log: $log" >&2; exit 1; }
if ! [[ "$speed" =~ ^[0-9]*[.]?[0-9]+$ ]] || awk -v s="$speed" 'BEGIN { exit !(s <= 0) }'; then
  echo "replay.sh: --speed must be a positive number, got '$speed'" >&2
  exit 1
fi
for tool in vimot-log-summary vimot-log-replay; do
  [ -x "$bin/$tool" ] || { echo "replay.sh: $bin/$tool not built (scripts/build.sh)" >&2; exit 1; }
done

if [ $offline -eq 1 ]; then
  channels=$("$bin/vimot-log-summary" "$log" | awk 'NR > 2 { print $1 }')
  procs=()
  grep -qx VINS_STATE <<< "$channels" && procs+=(--vins "$here/config/${VIMOT_VINS_CONFIG:-vins.yaml}")
  grep -qxE 'NAV_STATE|TARGET_STATE' <<< "$channels" && procs+=(--target-filter "$here/config/target_filter.yaml")
  if [ ${#procs[@]} -eq 0 ]; then
    echo "replay.sh: $log holds no VINS_STATE, NAV_STATE or TARGET_STATE to reproduce" >&2
    exit 2
  fi
  exec "$bin/vimot-log-replay" "$log" "${procs[@]}"
fi

recorded=$("$bin/vimot-log-summary" --speed "$log")
if awk -v r="$recorded" 'BEGIN { exit !(r > 0) }'; then
  factor=$(awk -v s="$speed" -v r="$recorded" 'BEGIN { printf "%.6g", s / r }')
else
  echo "replay.sh: the recorded speed of $log is unknown (no sensor channel spans any time); playing at -s $speed" >&2
  factor="$speed"
fi
echo "replay.sh: $log was recorded at ${recorded}x; playing channels $regex at ${speed}x (lcm-logplayer -s $factor)" >&2
if [ $stack -eq 1 ]; then
  out="${VIMOT_OUT:-$here/out/replay-$(date +%Y%m%d-%H%M%S)}"
  mkdir -p "$out"
  [ -n "$url" ] && export LCM_DEFAULT_URL="$url"
  export VIMOT_BIN="$bin" VIMOT_CONFIG="${VIMOT_CONFIG:-$here/config}" VIMOT_LOG="$out/replay.lcmlog"
  export VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins.yaml}" VIMOT_TARGET_CONFIG="${VIMOT_TARGET_CONFIG:-target_filter.yaml}"
  export VIMOT_REPLAY_LOG="$(cd "$(dirname "$log")" && pwd)/$(basename "$log")"
  export VIMOT_REPLAY_CHANNELS="$regex" VIMOT_REPLAY_SPEED="$factor"
  echo "replay.sh: running sheriff_configs/log_playback.pmd (output in $out/sheriff.txt)" >&2
  status=0
  "$bin/vimot-sheriff" --script run --exit-when player "$here/sheriff_configs/log_playback.pmd" \
    > "$out/sheriff.txt" 2>&1 || status=$?
  if [ $status -ne 0 ]; then
    echo "replay.sh: the sheriff exited with status $status; last lines of $out/sheriff.txt:" >&2
    tail -n 20 "$out/sheriff.txt" >&2
    exit $status
  fi
  "$bin/vimot-log-summary" "$VIMOT_LOG"
  exit 0
fi
args=(-s "$factor" -e "$regex")
[ -n "$url" ] && args+=("--lcm-url=$url")
exec lcm-logplayer "${args[@]}" "$log"

#!/usr/bin/env bash
# Kill-and-recover check of the simulated stereo stack
# (sheriff_configs/sim_demo.pmd: logger, vins, target_filter, sim; vins and
# target_filter with auto_respawn). Runs the stack once undisturbed, then once
# per victim, killing the victim with SIGKILL mid-run, and checks:
#   respawned   the sheriff (or deputy) started it again;
#   back        its output channel (vins: VINS_STATE; target_filter:
#               NAV_STATE) fell silent for at most 3 s in the log (lcm-logger's
#               wall clock), and the target filter's TARGET_STATE came back
#               (target re-acquired);
#   others      no other command exited, and the other estimator's output
#               never fell silent for more than 1 s;
#   accuracy    RMSE over the whole run (every updated state against the
#               ground truth, the re-initialisation included; vimot-log-eval)
#               of VINS_STATE, NAV_STATE and TARGET_STATE (the target in the
#               world and relative to the robot, its frame taken again at a
#               restart) at most 10 % above the undisturbed run's.
# Exits 0 if every check passed, 1 if one failed, 2 on a setup error.
#
# Usage: scripts/kill_recovery.sh [--deputy] [--victims "vins target_filter"]
#                                 [--kill-at SECONDS]
#   --deputy     run the commands through a vimot-deputy driven by
#                vimot-sheriff --lcm (procman's protocol) instead of locally
#   --victims    processes to kill, one run each (default: vins target_filter)
#   --kill-at S  wall-clock seconds after the simulator started (default 20)
# Environment: VIMOT_SPEED (default 2; a real-time run: not niced), VIMOT_SEED
# (1), VIMOT_SIM_CONFIG (sim_paper.yaml), VIMOT_OUT (out/kill-recovery-<date>),
# LCM_DEFAULT_URL (default a private group, port 7698, ttl=0).
# Details and measured figures: docs/sheriff.md ("Recovery").
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${VIMOT_BUILD_DIR:-$here/build}/bin"

mode=local
victims="vins target_filter"
kill_at=20
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    --deputy) mode=deputy; shift ;;
    --victims) victims="${2:?kill_recovery.sh: --victims needs names}"; shift 2 ;;
    --kill-at) kill_at="${2:?kill_recovery.sh: --kill-at needs seconds}"; shift 2 ;;
    *) echo "kill_recovery.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$kill_at" =~ ^[0-9]+([.][0-9]+)?$ ]] || { echo "kill_recovery.sh: --kill-at must be seconds" >&2; exit 2; }
for v in $victims; do
  case "$v" in
    vins|target_filter) ;;
    *) echo "kill_recovery.sh: cannot check '$v' (vins or target_filter; see docs/sheriff.md)" >&2; exit 2 ;;
  esac
done
for exe in vimot-sheriff vimot-deputy vimot-sim vimot-vins vimot-target-filter vimot-log-summary vimot-log-eval; do
  [ -x "$bin/$exe" ] || { echo "kill_recovery.sh: $bin/$exe not built (scripts/build.sh)" >&2; exit 2; }
done

export VIMOT_BIN="$bin" VIMOT_CONFIG="$here/config"
export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_paper.yaml}" VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins.yaml}"
export VIMOT_SPEED="${VIMOT_SPEED:-2}" VIMOT_SEED="${VIMOT_SEED:-1}"
export LCM_DEFAULT_URL="${LCM_DEFAULT_URL:-udpm://239.255.76.67:7698?ttl=0&recv_buf_size=4194304}"
pmd="$here/sheriff_configs/sim_demo.pmd"
out="${VIMOT_OUT:-$here/out/kill-recovery-$(date +%Y%m%d-%H%M%S)}"
mkdir -p "$out"
host="kill-recovery-$$"
# A safety cap only: a run ends when the simulator does.
cap=900

pids=()
cleanup() {
  local p
  for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
}
trap cleanup EXIT

# The first pid the sheriff output gives for command $2 after line $3 (0: none).
pid_of() {
  local file="$1" cmd="$2"
  if [ $mode = local ]; then
    grep -oE "(started|respawned) '$cmd' \(pid [0-9]+\)" "$file" | tail -n 1 | grep -oE '[0-9]+\)$' | tr -d ')'
  else
    grep -oE "\] $host:$cmd running \(pid [0-9]+\)" "$file" | tail -n 1 | grep -oE '[0-9]+\)$' | tr -d ')'
  fi
}
sim_started() {
  if [ $mode = local ]; then grep -q "started 'sim'" "$1"; else grep -q "\] $host:sim running" "$1"; fi
}
sim_ended() {
  if [ $mode = local ]; then grep -qE "'sim' (exited|ended)" "$1"; else grep -qE "\] $host:sim (stopped|exited)" "$1"; fi
}

# run NAME [VICTIM]: one run of the stack; kills VICTIM kill_at s after the simulator started.
run() {
  local name="$1" victim="${2:-}" dir="$out/$1"
  mkdir -p "$dir"
  export VIMOT_LOG="$dir/run.lcmlog"
  local sheriff deputy=""
  if [ $mode = local ]; then
    "$bin/vimot-sheriff" --script run --exit-when sim --duration "$cap" "$pmd" > "$dir/sheriff.txt" 2>&1 &
    sheriff=$!
  else
    "$bin/vimot-deputy" --name "$host" > "$dir/deputy.txt" 2>&1 &
    deputy=$!
    pids+=("$deputy")
    sleep 1
    "$bin/vimot-sheriff" --lcm --local-host "$host" --script run --duration "$cap" "$pmd" > "$dir/sheriff.txt" 2>&1 &
    sheriff=$!
  fi
  pids+=("$sheriff")
  local t=0
  until sim_started "$dir/sheriff.txt"; do
    sleep 0.1; t=$((t + 1))
    [ $t -lt 300 ] || { echo "$name: the simulator did not start; see $dir/sheriff.txt" >&2; return 1; }
  done
  if [ -n "$victim" ]; then
    sleep "$kill_at"
    local pid
    pid=$(pid_of "$dir/sheriff.txt" "$victim")
    [ -n "$pid" ] || { echo "$name: no pid for $victim in $dir/sheriff.txt" >&2; return 1; }
    kill -9 "$pid"
    echo "$pid $(date +%s%6N)" > "$dir/killed"
    echo "   killed $victim (pid $pid) with SIGKILL"
  fi
  until sim_ended "$dir/sheriff.txt" || ! kill -0 "$sheriff" 2>/dev/null; do sleep 0.2; done
  # Local: --exit-when sim ends the sheriff; through a deputy, stop it.
  kill -INT "$sheriff" 2>/dev/null || true
  wait "$sheriff" || true
  if [ -n "$deputy" ]; then kill -INT "$deputy" 2>/dev/null || true; wait "$deputy" || true; fi
  pids=()
  "$bin/vimot-log-summary" --gaps "$VIMOT_LOG" > "$dir/summary.txt" || true
  "$bin/vimot-log-eval" "$VIMOT_LOG" > "$dir/vins_eval.txt" 2>&1 || true
  "$bin/vimot-log-eval" "$VIMOT_LOG" --state-channel NAV_STATE --target-channel TARGET_STATE --own-target-frame \
    --target-restart-gap 0.5 > "$dir/target_eval.txt" 2>&1 || true
}

gap() { awk -v c="$2" '$1 == c { print $7 }' "$1/summary.txt"; }
rmse_vio() { awk '$1 == "samples" { print $5 }' "$1/$2"; }
rmse_target() { awk -v w="$2" '$0 ~ "^target in " w { for (i = 1; i <= NF; ++i) if ($i == "RMSE") { print $(i + 1); exit } }' "$1/target_eval.txt"; }
metric() {  # metric NAME DIR
  case "$1" in
    VINS_STATE) rmse_vio "$2" vins_eval.txt ;;
    NAV_STATE) rmse_vio "$2" target_eval.txt ;;
    TARGET_STATE) rmse_target "$2" world ;;
    TARGET_IN_IMU) rmse_target "$2" IMU ;;
  esac
}

failures=0
check() {  # check CONDITION_STATUS TEXT
  if [ "$1" -eq 0 ]; then echo "   ok    $2"; else echo "   FAIL  $2"; failures=$((failures + 1)); fi
}
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && b != "" && a + 0 <= b + 0) }'; }

echo "== kill and recover ($mode), $VIMOT_SIM_CONFIG at ${VIMOT_SPEED}x, seed $VIMOT_SEED, kill at ${kill_at} s; output in $out"
echo "== undisturbed run"
run undisturbed
for ch in VINS_STATE NAV_STATE TARGET_STATE; do
  echo "   $ch position RMSE $(metric $ch "$out/undisturbed") m, longest silence $(gap "$out/undisturbed" $ch) s"
done
echo "   TARGET_STATE target in the IMU frame: position RMSE $(metric TARGET_IN_IMU "$out/undisturbed") m"
for victim in $victims; do
  echo "== kill $victim"
  run "kill_$victim" "$victim"
  d="$out/kill_$victim"
  if [ $mode = local ]; then
    grep -q "respawned '$victim'" "$d/sheriff.txt"; check $? "$victim respawned"
    others=$(grep -E "\[sheriff\] '[a-z_]+' exited" "$d/sheriff.txt" | grep -vE "'($victim|sim)' exited" || true)
  else
    n=$(grep -oE "\] $host:$victim running \(pid [0-9]+\)" "$d/sheriff.txt" | sort -u | wc -l)
    [ "$n" -ge 2 ]; check $? "$victim respawned ($n runs)"
    others=$(grep -E "\] $host:[a-z_]+ exited" "$d/sheriff.txt" | grep -vE ":($victim|sim) exited" || true)
  fi
  [ -z "$others" ]; check $? "no other command exited${others:+: $others}"
  if [ "$victim" = vins ]; then own=VINS_STATE; other=NAV_STATE; else own=NAV_STATE; other=VINS_STATE; fi
  g=$(gap "$d" $own); le "$g" 3; check $? "$own back within 3 s (longest silence $g s)"
  g=$(gap "$d" TARGET_STATE)
  if [ "$victim" = target_filter ]; then
    grep -qE "target restarts \(gaps above 0.5 s\): [1-9]" "$d/target_eval.txt"
    check $? "target re-acquired (TARGET_STATE silent $g s, $(grep -oE 'target restarts.*: [0-9]+' "$d/target_eval.txt" | grep -oE '[0-9]+$') restart)"
  fi
  g=$(gap "$d" $other); le "$g" 1; check $? "$other never silent over 1 s (longest $g s)"
  for ch in VINS_STATE NAV_STATE TARGET_STATE TARGET_IN_IMU; do
    a=$(metric $ch "$d"); b=$(metric $ch "$out/undisturbed")
    limit=$(awk -v b="$b" 'BEGIN { print 1.1 * b }')
    le "$a" "$limit"; check $? "$ch position RMSE $a m <= 1.1 x undisturbed $b m"
  done
done
trap - EXIT
if [ $failures -eq 0 ]; then echo "== all checks passed"; exit 0; fi
echo "== $failures checks failed" >&2
exit 1

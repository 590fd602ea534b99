#!/usr/bin/env bash
# Kill-and-recover check of the simulated stereo stack
# (sheriff_configs/sim_demo.pmd: logger, vins, target_filter, sim; all with
# auto_respawn). Runs the stack once undisturbed, then once per victim,
# killing the victim with SIGKILL mid-run, and checks:
#   respawned   the sheriff (or deputy) started it again;
#   back        its outputs (vins: VINS_STATE; target_filter: NAV_STATE and
#               TARGET_STATE; sim: IMU and every estimate; logger: the log
#               itself, IMU and every estimate) fell silent for at most 3 s
#               in the log (the logger's wall clock);
#   others      no other command exited, and the other estimator's outputs
#               never fell silent for more than 1 s;
#   kept        the estimate survived: a killed vins or target_filter
#               restored its whole state (the target filter's with its
#               target) from its checkpoint (--checkpoint in sim_demo.pmd,
#               under /dev/shm) and caught up on the input it missed from
#               the run's log (--catch-up-log), after a simulator kill both
#               estimators bridged the outage, a killed logger appended to
#               the run's log; neither estimator reset;
#   accuracy    position RMSE (vimot-log-eval: every updated state of the
#               run against the ground truth; the target in the world and
#               relative to the robot, in one target frame for the run) of
#               VINS_STATE, NAV_STATE and TARGET_STATE at most 10 % above the
#               undisturbed run's.
#   replay      every output equals the offline replay of the run's logged
#               inputs through the same Nodes (vimot-log-replay): the live
#               run did what the estimators do offline on that input (not
#               after a logger kill: the log lacks the input of its outage,
#               which the estimators had).
# Exits 0 if every check passed, 1 if one failed, 2 on a setup error.
#
# Usage: scripts/kill_recovery.sh [--deputy] [--victims "vins target_filter sim logger"]
#                                 [--kill-at SECONDS]
#   --deputy     run the commands through a vimot-deputy driven by
#                vimot-sheriff --lcm (procman's protocol) instead of locally
#   --victims    processes to kill, one run each (default: all four)
#   --kill-at S  wall-clock seconds after the simulator started (default 20)
# Environment: VIMOT_SPEED (default 1; a real-time run: not niced), VIMOT_SEED
# (1), VIMOT_SIM_CONFIG (sim_paper.yaml), VIMOT_OUT (out/kill-recovery-<date>),
# LCM_DEFAULT_URL (default a private group, port 7698, ttl=0).
# Details and measured figures: docs/sheriff.md ("Recovery").
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${VIMOT_BUILD_DIR:-$here/build}/bin"
# shellcheck source=scripts/run_figures.sh
source "$here/scripts/run_figures.sh"  # evaluate, rmse_vio, rmse_target, target_key

mode=local
victims="vins target_filter sim logger"
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
    vins|target_filter|sim|logger) ;;
    *) echo "kill_recovery.sh: cannot check '$v' (vins, target_filter, sim or logger; see docs/sheriff.md)" >&2; exit 2 ;;
  esac
done
for exe in vimot-sheriff vimot-deputy vimot-sim vimot-vins vimot-target-filter vimot-log-summary vimot-log-eval vimot-log-replay; do
  [ -x "$bin/$exe" ] || { echo "kill_recovery.sh: $bin/$exe not built (scripts/build.sh)" >&2; exit 2; }
done

export VIMOT_BIN="$bin" VIMOT_CONFIG="$here/config"
export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_paper.yaml}" VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins.yaml}"
export VIMOT_SPEED="${VIMOT_SPEED:-1}" VIMOT_SEED="${VIMOT_SEED:-1}"
# sim_demo.pmd's target filter mode: the config's, as the replays below use it.
export VIMOT_TARGET_MODE="$(target_key mode)"
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
  rm -f /dev/shm/vimot-kill-recovery-$$-*
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
# Through a deputy (no --exit-when in --lcm mode): the simulator has sent its
# last message (it lingers 2 s for the consumers, then exits, and would be
# respawned: the script stops the sheriff before that).
sim_done() { grep -qE "^\[$host:sim\] .*done: " "$1"; }

# run NAME [VICTIM]: one run of the stack; kills VICTIM kill_at s after the simulator started.
run() {
  local name="$1" victim="${2:-}" dir="$out/$1"
  mkdir -p "$dir"
  export VIMOT_LOG="$dir/run.lcmlog"
  rm -f "$VIMOT_LOG"  # the logger appends (a respawned one keeps the record)
  # Checkpoints on a RAM file system: rewritten after every update, they
  # must not compete with the log's disk writes (docs/sheriff.md).
  export VIMOT_CKPT="/dev/shm/vimot-kill-recovery-$$-$name"
  local sheriff deputy=""
  : > "$dir/sheriff.txt"
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
  if [ $mode = deputy ]; then
    until sim_done "$dir/sheriff.txt" || ! kill -0 "$sheriff" 2>/dev/null; do sleep 0.2; done
    sleep 1.5
    kill -INT "$sheriff" 2>/dev/null || true
  fi
  # Locally --exit-when sim ends the run.
  wait "$sheriff" || true
  if [ -n "$deputy" ]; then kill -INT "$deputy" 2>/dev/null || true; wait "$deputy" || true; fi
  pids=()
  rm -f "$VIMOT_CKPT".*.ckpt "$VIMOT_CKPT".*.ckpt.tmp
  "$bin/vimot-log-summary" --gaps "$VIMOT_LOG" > "$dir/summary.txt" || true
  # One target frame for the whole run: every victim's restart keeps the target.
  evaluate "$dir" "$VIMOT_LOG"
  # The same inputs through the same Nodes offline: the live outputs must be
  # these, bit for bit (after a simulator kill: what scripts/outage_sweep.sh
  # measures for an outage of that length over seeds).
  local rc=0
  "$bin/vimot-log-replay" --vins "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" --target-filter "$VIMOT_CONFIG/target_filter.yaml" \
    "$VIMOT_LOG" > "$dir/replay.txt" 2>&1 || rc=$?
  echo "$rc" > "$dir/replay.rc"
}


gap() { awk -v c="$2" '$1 == c { print $7 }' "$1/summary.txt"; }
metric() {  # metric NAME DIR
  case "$1" in
    VINS_STATE) rmse_vio "$2" vins_eval.txt ;;
    NAV_STATE) rmse_vio "$2" target_eval.txt ;;
    TARGET_STATE) rmse_target "$2" world ;;
    TARGET_IN_IMU) rmse_target "$2" IMU ;;
  esac
}

failures=0
check() {  # check TEXT COMMAND...: ok if COMMAND succeeds
  local text="$1"
  shift
  if "$@"; then echo "   ok    $text"; else echo "   FAIL  $text"; failures=$((failures + 1)); fi
}
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a != "" && b != "" && a + 0 <= b + 0) }'; }

# Input the estimators lost (UDP under load; their "stopping:" lines): a
# run that lost input is not the stack's undisturbed accuracy.
losses() {
  local p
  for p in vins target_filter; do
    printf ' %s %s' "$p" "$(grep -E "^\[([^]]*:)?$p\] .*stopping: in" "$1/sheriff.txt" |
      sed -n 's/.* lost \([0-9]*\).*/\1/p' | awk '{ n += $1 } END { print n + 0 }')"
  done
}

echo "== kill and recover ($mode), $VIMOT_SIM_CONFIG at ${VIMOT_SPEED}x, seed $VIMOT_SEED, kill at ${kill_at} s; output in $out"
echo "== undisturbed run"
run undisturbed
for ch in VINS_STATE NAV_STATE TARGET_STATE; do
  echo "   $ch position RMSE $(metric $ch "$out/undisturbed") m, longest silence $(gap "$out/undisturbed" $ch) s"
done
echo "   TARGET_STATE target in the IMU frame: position RMSE $(metric TARGET_IN_IMU "$out/undisturbed") m"
echo "   IMU/FEATURES messages lost under load:$(losses "$out/undisturbed")"
check "every output equals its offline replay (vimot-log-replay, $out/undisturbed/replay.txt)" \
  [ "$(cat "$out/undisturbed/replay.rc")" = 0 ]
# said FILE PROCESS TEXT: PROCESS logged a line with TEXT.
said() { grep -qE "^\[([^]]*:)?$2\] .*$3" "$1"; }
# ratio CHANNEL DIR_A DIR_B: "a m <= 1.1 x b m" check of metric CHANNEL.
ratio() {
  local a b
  a=$(metric "$1" "$2"); b=$(metric "$1" "$3")
  check "$1 position RMSE $a m against $b m ($(awk -v a="$a" -v b="$b" 'BEGIN { if (b > 0) printf "%+.0f %%", 100 * (a / b - 1) }')), at most +10 %" \
    le "$a" "$(awk -v b="$b" 'BEGIN { print 1.1 * b }')"
}

for victim in $victims; do
  echo "== kill $victim"
  run "kill_$victim" "$victim"
  d="$out/kill_$victim"
  echo "   IMU/FEATURES messages lost under load:$(losses "$d")"
  if [ $mode = local ]; then
    check "$victim respawned" grep -q "respawned '$victim'" "$d/sheriff.txt"
    others=$(grep -E "\[sheriff\] '[a-z_]+' exited" "$d/sheriff.txt" | grep -vE "'$victim' exited|'sim' exited with code 0" || true)
  else
    n=$(grep -oE "\] $host:$victim running \(pid [0-9]+\)" "$d/sheriff.txt" | sort -u | wc -l)
    check "$victim respawned ($n runs)" [ "$n" -ge 2 ]
    others=$(grep -E "\] $host:[a-z_]+ exited" "$d/sheriff.txt" | grep -vE ":$victim exited|:sim exited with code 0" || true)
  fi
  check "no other command exited${others:+: $others}" [ -z "$others" ]
  case "$victim" in
    vins) back="VINS_STATE"; steady="NAV_STATE TARGET_STATE" ;;
    target_filter) back="NAV_STATE TARGET_STATE"; steady="VINS_STATE" ;;
    sim|logger) back="IMU VINS_STATE NAV_STATE TARGET_STATE"; steady="" ;;
  esac
  for ch in $back; do g=$(gap "$d" $ch); check "$ch back within 3 s (longest silence $g s)" le "$g" 3; done
  for ch in $steady; do g=$(gap "$d" $ch); check "$ch never silent over 1 s (longest $g s)" le "$g" 1; done
  # The estimate survived the kill: restored from the checkpoint, or the
  # outage bridged; no estimator reset.
  if [ "$victim" = sim ]; then
    for p in vins target_filter; do check "$p bridged the outage" said "$d/sheriff.txt" $p "bridged, the estimate kept"; done
  elif [ "$victim" = logger ]; then
    check "the logger appended to the run's log" said "$d/sheriff.txt" logger "appending to"
  else
    check "$victim restored its checkpoint" said "$d/sheriff.txt" "$victim" "restored from checkpoint"
    check "$victim caught up from the log" said "$d/sheriff.txt" "$victim" "caught up "
  fi
  for p in vins target_filter; do
    check "$p did not reset" eval "! said '$d/sheriff.txt' $p 'reset, re-initialising'"
  done
  if [ "$victim" = logger ]; then
    echo "   --    offline replay not compared: the log lacks the input of the logger's outage"
  else
    check "every output equals its offline replay (vimot-log-replay, $d/replay.txt)" [ "$(cat "$d/replay.rc")" = 0 ]
  fi
  echo "   accuracy over the whole run against the undisturbed run:"
  for ch in VINS_STATE NAV_STATE TARGET_STATE TARGET_IN_IMU; do ratio $ch "$d" "$out/undisturbed"; done
done
trap - EXIT
if [ $failures -eq 0 ]; then echo "== all checks passed"; exit 0; fi
echo "== $failures checks failed" >&2
exit 1

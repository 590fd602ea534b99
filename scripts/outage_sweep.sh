#!/usr/bin/env bash
# What an input outage costs the stereo stack, over seeds and outage times,
# offline: the simulator's log with and without an outage of every stream
# (vimot-sim --outage-at/--outage-length: what a simulator killed and
# respawned by the sheriff skips, docs/sheriff.md "Recovery"), each replayed
# through the vins and target_filter Nodes (vimot-log-replay, bit for bit
# the live processes) and scored as scripts/kill_recovery.sh scores a kill
# (vimot-log-eval: whole-run position RMSE of VINS_STATE, NAV_STATE, the
# target in the world and in the IMU frame, one target frame per run).
# Prints one row per seed × outage time and the mean and spread of each
# change against the undisturbed run of the same seed.
#
# Usage: scripts/outage_sweep.sh [--seeds "1 2 3"] [--at "21.0"] [--length 1.1] [--jobs 2]
#   --seeds   simulator seeds (default 1–10)
#   --at      outage start(s), s after the run's start (default 21.0: a kill
#             20 s after a 1 s start delay, as kill_recovery.sh)
#   --length  outage length, s (default 1.1: a respawn's)
#   --jobs    runs in parallel (default: the core count)
# Environment: VIMOT_SIM_CONFIG (sim_paper.yaml), VIMOT_OUT (out/outage-sweep-<date>).
# Exits 0, 1 if a run failed, 2 on a setup error.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${VIMOT_BUILD_DIR:-$here/build}/bin"
# shellcheck source=scripts/run_figures.sh
source "$here/scripts/run_figures.sh"  # evaluate, rmse_vio, rmse_target

seeds="$(seq -s ' ' 1 10)"
at_list="21.0"
length=1.1
jobs="$(nproc)"
while [ $# -gt 0 ]; do
  case "$1" in
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    --seeds) seeds="${2:?outage_sweep.sh: --seeds needs numbers}"; shift 2 ;;
    --at) at_list="${2:?outage_sweep.sh: --at needs seconds}"; shift 2 ;;
    --length) length="${2:?outage_sweep.sh: --length needs seconds}"; shift 2 ;;
    --jobs) jobs="${2:?outage_sweep.sh: --jobs needs a number}"; shift 2 ;;
    *) echo "outage_sweep.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
for exe in vimot-sim vimot-log-replay vimot-log-eval; do
  [ -x "$bin/$exe" ] || { echo "outage_sweep.sh: $bin/$exe not built (scripts/build.sh)" >&2; exit 2; }
done
config="$here/config"
sim_config="$config/${VIMOT_SIM_CONFIG:-sim_paper.yaml}"
out="${VIMOT_OUT:-$here/out/outage-sweep-$(date +%Y%m%d-%H%M%S)}"
mkdir -p "$out"

# run_one DIR SEED [AT]: simulate (with an outage at AT if given), replay, score.
run_one() {
  local dir="$1" seed="$2" at="${3:-}"
  mkdir -p "$dir"
  local outage=()
  [ -n "$at" ] && outage=(--outage-at "$at" --outage-length "$length")
  "$bin/vimot-sim" --config "$sim_config" --seed "$seed" "${outage[@]}" --log "$dir/sim.lcm" \
    > "$dir/sim.txt" 2>&1 || { echo "outage_sweep.sh: vimot-sim failed, see $dir/sim.txt" >&2; return 1; }
  # Exit 2 = no recorded outputs to compare with: a simulator log has none.
  local rc=0
  "$bin/vimot-log-replay" --vins "$config/vins.yaml" --target-filter "$config/target_filter.yaml" \
    --out "$dir/replayed.lcm" "$dir/sim.lcm" > "$dir/replay.txt" 2>&1 || rc=$?
  [ "$rc" = 0 ] || [ "$rc" = 2 ] || { echo "outage_sweep.sh: replay failed, see $dir/replay.txt" >&2; return 1; }
  evaluate "$dir" "$dir/replayed.lcm"
  rm -f "$dir/sim.lcm" "$dir/replayed.lcm"
}

runs=()
for s in $seeds; do
  runs+=("$out/seed$s/undisturbed $s")
  for a in $at_list; do runs+=("$out/seed$s/outage_at_$a $s $a"); done
done
echo "outage_sweep: ${#runs[@]} runs (seeds: $seeds; outage ${length} s at: $at_list) on $jobs jobs, in $out"
export -f run_one evaluate
export bin config sim_config length
failed=0
printf '%s\n' "${runs[@]}" | xargs -P "$jobs" -L 1 bash -c 'run_one "$0" "$@" && echo "  done $0"' || failed=1

figures() { echo "$(rmse_vio "$1" vins_eval.txt) $(rmse_vio "$1" target_eval.txt) $(rmse_target "$1" world) $(rmse_target "$1" IMU)"; }

{
  echo "seed at_s  undisturbed: VINS NAV target_world target_in_IMU [m]  outage: VINS NAV target_world target_in_IMU [m]"
  for s in $seeds; do
    base="$(figures "$out/seed$s/undisturbed")"
    for a in $at_list; do echo "$s $a $base $(figures "$out/seed$s/outage_at_$a")"; done
  done
} > "$out/table.txt"
awk 'NR == 1 { next }
     NF != 10 { printf "seed %s at %s: figures missing\n", $1, $2; bad = 1; next }
     { n++; printf "seed %2s  outage %s s at %5s s:", $1, L, $2
       for (k = 0; k < 4; ++k) { d = 100 * ($(7 + k) / $(3 + k) - 1); s1[k] += d; s2[k] += d * d
                                 if (d > 10) over[k]++
                                 printf "  %+6.1f %%", d }
       printf "\n" }
     END { if (n == 0) exit 1
           names[0] = "VINS"; names[1] = "NAV"; names[2] = "target world"; names[3] = "target in IMU"
           printf "over %d runs, change against the undisturbed run of the same seed (mean, std, runs above +10 %%):\n", n
           for (k = 0; k < 4; ++k) { m = s1[k] / n; v = s2[k] / n - m * m
                                     printf "  %-14s %+6.1f %%  %5.1f %%  %d\n", names[k], m, sqrt(v > 0 ? v : 0), over[k] }
           exit bad }' L="$length" "$out/table.txt" | tee "$out/summary.txt" || failed=1
exit "$failed"

# Sourced by scripts/kill_recovery.sh, scripts/outage_sweep.sh and
# scripts/demo.sh: how they score a run's log (vimot-log-eval; needs $bin, the
# executables' folder) and read the target filter's config.

# target_key KEY: the value of target.KEY in $VIMOT_CONFIG/target_filter.yaml
# (a key of the target: section itself, e.g. mode, representation, sigma_t).
target_key() { sed -n "s/^  $1: *\([a-z0-9.]*\).*/\1/p" "$VIMOT_CONFIG/target_filter.yaml" | head -n 1; }

# evaluate DIR LOG: vimot-log-eval of VINS_STATE and of NAV_STATE + TARGET_STATE
# (the target in one frame of the filter's own for the whole run).
evaluate() {
  local dir="$1" log="$2"
  "$bin/vimot-log-eval" "$log" > "$dir/vins_eval.txt" 2>&1 || true
  "$bin/vimot-log-eval" "$log" --state-channel NAV_STATE --target-channel TARGET_STATE --own-target-frame \
    > "$dir/target_eval.txt" 2>&1 || true
}
# rmse_vio DIR FILE: position RMSE of an evaluate() output.
rmse_vio() { awk '$1 == "samples" { print $5 }' "$1/$2"; }
# rmse_target DIR world|IMU: target position RMSE in that frame.
rmse_target() { awk -v w="$2" '$0 ~ "^target in " w { for (i = 1; i <= NF; ++i) if ($i == "RMSE") { print $(i + 1); exit } }' "$1/target_eval.txt"; }

# Sourced by scripts/kill_recovery.sh and scripts/outage_sweep.sh: how both
# score a run's log (vimot-log-eval; needs $bin, the executables' folder).

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

#!/usr/bin/env bash
# The README's main job: the simulated scenario through the LCM stack.
#   scripts/demo.sh        stereo target tracking (Schmidt-EKF paper)
#   scripts/demo.sh mono   monocular metric scale (scale paper)
#   scripts/demo.sh pixels stereo target tracking from rendered images with no
#                          ground truth in the chain: the simulator renders, the
#                          segmentation network finds the target, the mask
#                          filter its box, the feature tracker makes FEATURES
#   scripts/demo.sh pixels-truthbox  the same with the simulator's true target
#                          box instead of the network and the mask filter
#   scripts/demo.sh mono-pixels  monocular metric scale from rendered images
#   scripts/demo.sh mono-segmented  the same with no ground truth in the chain
#                          (segmenter network, mask filter)
# Installs what is missing, builds, starts the processes of a sheriff config
# with vimot-sheriff and prints a summary: processes, messages per channel,
# the accuracy of the LCM run against ground truth, the same scenario run
# offline (in-process, same libraries) for comparison, and the log path.
# Prints, per process and input channel, what was published, received and
# counted as lost (scripts/demo_input_report.sh; every process drains or
# counts the input still queued when it is stopped, docs/robustness.md).
# Exits 5 if those counts are not exact (input lost silently), else 4 if
# the LCM run's VIO or target figures differ from the offline run's (a
# relative difference above 1e-6: input lost or late under load).
#  - default: sheriff_configs/sim_demo.pmd (simulator, vins, the target
#    filter, vimot-logger): VIO and target accuracy.
#  - mono: sheriff_configs/sim_mono.pmd (simulator, vins, object tracker,
#    scale estimator, vimot-logger): VIO accuracy, scale error, the metric
#    object pose error in the world and that of the object motion filter.
#  - pixels: sheriff_configs/sim_segmented.pmd (simulator rendering images,
#    segmenter with the shipped network, mask filter, feature tracker on the
#    mask filter's box, vins, target filter, vimot-logger;
#    docs/segmented_pipeline.md): VIO and target accuracy of the LCM run
#    against the same seed's offline run of the same chain (vimot-vio-eval /
#    vimot-target-eval --pixels --segmenter --mask-filter), the target box
#    against the true one, and the accuracy next to the feature-level runs
#    of that seed.
#  - pixels-truthbox: sheriff_configs/sim_pixels.pmd (feature tracker with
#    the true target box): the same comparisons with the offline run from
#    pixels (--pixels only).
#  - mono-pixels: sheriff_configs/sim_mono_pixels.pmd (simulator rendering
#    cam0, feature tracker with the true target box, vins, object tracker,
#    scale estimator, vimot-logger): VIO accuracy and the scale figures of the
#    LCM run against the same seed's offline runs from pixels
#    (vimot-vio-eval --pixels, vimot-scale-eval --pixels); exits 4 if
#    either differs.
#  - mono-segmented: sheriff_configs/sim_mono_segmented.pmd (mono-pixels with
#    the segmenter's network and the mask filter giving the target box and
#    mask, no ground truth in the chain), compared likewise.
#
# Environment (all optional):
#   VIMOT_SIM_CONFIG  scenario file in config/ (default sim_paper.yaml; mono:
#                     sim_mono.yaml)
#   VIMOT_SPEED       simulator real-time factor (default 2; mono and
#                     pixels-truthbox: 1, the object tracker's bundle
#                     adjustment takes ≈ 20 ms per frame; pixels: 0.25, the
#                     network takes ≈ 70 ms per image; mono-pixels: 0.5, the
#                     object tracker takes ≈ 13 ms per frame there,
#                     docs/scale_estimator.md; mono-segmented: 0.2, the
#                     network at 20 images per simulated second;
#                     on 2 cores at 4x UDP already loses IMU messages, which
#                     the heartbeats count, and the demo then fails)
#   VIMOT_SEED        noise seed (default 1)
#   VIMOT_DURATION    pixels: seconds to simulate (default 30; mono-pixels and mono-segmented 60,
#                     the scale estimator's 40 s window needs most of it; rendering and
#                     tracking cost ≈ 25 ms per stereo frame, so the default
#                     speed there is 1)
#   VIMOT_TARGET_MODE default pipeline: the target filter's mode, ekf, skf,
#                     adaptive or off (default: config/target_filter.yaml's)
#   VIMOT_VINS_CONFIG estimator file in config/ (default vins.yaml; mono:
#                     vins_mono.yaml)
#   VIMOT_SEGMENTER_CONFIG  pixels: segmenter file in config/ (default
#                     segmenter.yaml, the network; segmenter_truth.yaml: the
#                     true masks with dropouts and false blobs)
#   VIMOT_OUT         output folder (default out/demo-<date>)
#   LCM_DEFAULT_URL   LCM network (default
#                     udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304: never
#                     leaves this machine; 4 MiB receive buffers (capped by the
#                     kernel's net.core.rmem_max) so a process that stalls for a
#                     moment under load does not lose UDP packets)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIMOT_BUILD_DIR:-$here/build}"

pipeline=target
case "${1:-}" in
  -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
  mono) pipeline=mono ;;
  pixels) pipeline=pixels ;;
  pixels-truthbox) pipeline=pixels-truthbox ;;
  mono-pixels) pipeline=mono_pixels ;;
  mono-segmented) pipeline=mono_segmented ;;
  "") ;;
  *) echo "demo.sh: unknown argument '$1' (expected nothing, 'mono', 'pixels', 'pixels-truthbox', 'mono-pixels', 'mono-segmented' or --help)" >&2; exit 1 ;;
esac

"$here/scripts/build.sh"

export VIMOT_BIN="$build/bin"
export VIMOT_CONFIG="$here/config"
# shellcheck source=scripts/run_figures.sh
source "$here/scripts/run_figures.sh"  # target_key
if [ $pipeline = mono ]; then
  pmd="$here/sheriff_configs/sim_mono.pmd"
  export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_mono.yaml}"
  export VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins_mono.yaml}"
  export VIMOT_SPEED="${VIMOT_SPEED:-1}"
elif [ $pipeline = pixels ]; then
  pmd="$here/sheriff_configs/sim_segmented.pmd"
  export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_paper.yaml}"
  export VIMOT_TRACKER_CONFIG="${VIMOT_TRACKER_CONFIG:-feature_tracker_segmented.yaml}"
  export VIMOT_SEGMENTER_CONFIG="${VIMOT_SEGMENTER_CONFIG:-segmenter.yaml}"
  export VIMOT_MASK_FILTER_CONFIG="${VIMOT_MASK_FILTER_CONFIG:-mask_filter.yaml}"
  export VIMOT_DURATION="${VIMOT_DURATION:-30}"
  export VIMOT_SPEED="${VIMOT_SPEED:-0.25}"
elif [ $pipeline = pixels-truthbox ]; then
  pmd="$here/sheriff_configs/sim_pixels.pmd"
  export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_paper.yaml}"
  export VIMOT_TRACKER_CONFIG="${VIMOT_TRACKER_CONFIG:-feature_tracker_sim.yaml}"
  export VIMOT_DURATION="${VIMOT_DURATION:-30}"
  export VIMOT_SPEED="${VIMOT_SPEED:-1}"
elif [ $pipeline = mono_pixels ]; then
  pmd="$here/sheriff_configs/sim_mono_pixels.pmd"
  export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_mono.yaml}"
  export VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins_mono.yaml}"
  # The tracker config sim_mono_pixels.pmd runs (the offline runs take it too).
  export VIMOT_TRACKER_CONFIG=feature_tracker_sim_mono.yaml
  export VIMOT_DURATION="${VIMOT_DURATION:-60}"
  export VIMOT_SPEED="${VIMOT_SPEED:-0.5}"
elif [ $pipeline = mono_segmented ]; then
  pmd="$here/sheriff_configs/sim_mono_segmented.pmd"
  export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_mono.yaml}"
  export VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins_mono.yaml}"
  # The configs sim_mono_segmented.pmd runs (the offline runs take them too).
  export VIMOT_TRACKER_CONFIG=feature_tracker_segmented_mono.yaml
  export VIMOT_SEGMENTER_CONFIG=segmenter_mono.yaml
  export VIMOT_MASK_FILTER_CONFIG=mask_filter_mono.yaml
  export VIMOT_DURATION="${VIMOT_DURATION:-60}"
  export VIMOT_SPEED="${VIMOT_SPEED:-0.2}"
else
  pmd="$here/sheriff_configs/sim_demo.pmd"
  export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_paper.yaml}"
  # target.mode of config/target_filter.yaml unless overridden (--mode of vimot-target-filter).
  export VIMOT_TARGET_MODE="${VIMOT_TARGET_MODE:-$(target_key mode)}"
fi
if [ -n "${VIMOT_TARGET_MODE:-}" ] && [ "$pmd" != "$here/sheriff_configs/sim_demo.pmd" ]; then
  echo "demo.sh: VIMOT_TARGET_MODE applies to the default pipeline only (sheriff_configs/sim_demo.pmd)" >&2
  exit 2
fi
export VIMOT_SPEED="${VIMOT_SPEED:-2}"
export VIMOT_SEED="${VIMOT_SEED:-1}"
export VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins.yaml}"
export LCM_DEFAULT_URL="${LCM_DEFAULT_URL:-udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304}"
out="${VIMOT_OUT:-$here/out/demo-$(date +%Y%m%d-%H%M%S)}"
mkdir -p "$out"
export VIMOT_LOG="$out/demo.lcmlog"
# sim_demo.pmd's logger appends (so a respawned one keeps the record): start
# each run with no log.
rm -f "$VIMOT_LOG"
# The estimators' checkpoints (sim_demo.pmd), rewritten after every update:
# on a RAM file system, off the disk the log is written to; removed at the end.
export VIMOT_CKPT="/dev/shm/vimot-demo-$$"

echo "== vimot demo: $VIMOT_SIM_CONFIG at ${VIMOT_SPEED}x real time, seed $VIMOT_SEED"
echo "== processes ($(basename "$pmd")):"
"$VIMOT_BIN/vimot-sheriff" --list "$pmd" | sed 's/^/   /'
echo "== running (output in $out/sheriff.txt)"
set +e
"$VIMOT_BIN/vimot-sheriff" --script run --exit-when sim "$pmd" > "$out/sheriff.txt" 2>&1
status=$?
set -e
rm -f "$VIMOT_CKPT".*.ckpt "$VIMOT_CKPT".*.ckpt.tmp
grep -E '\[sim\].*(scenario|done|stopped)' "$out/sheriff.txt" | sed 's/^/   /' || true
if [ $status -ne 0 ]; then
  echo "demo: the sheriff exited with status $status; last lines of $out/sheriff.txt:" >&2
  tail -n 20 "$out/sheriff.txt" >&2
  exit $status
fi

echo "== messages per channel in the log:"
"$VIMOT_BIN/vimot-log-summary" "$VIMOT_LOG" | sed 's/^/   /'
echo "== VIO accuracy of the LCM run (VINS_STATE vs GROUND_TRUTH):"
perturb_seed=$(sed -n 's/^ *perturb_seed: *\([0-9]*\).*/\1/p' "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" | head -n 1)
# The same seed offline, in-process: the figures the LCM run must equal.
offline_args=()
if [ $pipeline = pixels ] || [ $pipeline = pixels-truthbox ] || [ $pipeline = mono_pixels ] || [ $pipeline = mono_segmented ]; then
  offline_args=(--duration "$VIMOT_DURATION" --pixels "$VIMOT_CONFIG/$VIMOT_TRACKER_CONFIG")
fi
if [ $pipeline = pixels ] || [ $pipeline = mono_segmented ]; then
  offline_args+=(--segmenter "$VIMOT_CONFIG/$VIMOT_SEGMENTER_CONFIG" --mask-filter "$VIMOT_CONFIG/$VIMOT_MASK_FILTER_CONFIG")
fi
"$VIMOT_BIN/vimot-vio-eval" --sim-config "$VIMOT_CONFIG/$VIMOT_SIM_CONFIG" \
  --vins-config "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" --runs 1 --first-seed "$VIMOT_SEED" \
  --perturb-seed "${perturb_seed:-0}" "${offline_args[@]}" --out "$out/offline" --quiet > "$out/offline.txt" 2>&1 || true
# Every LCM figure must equal the offline one: a difference (lost or late
# messages) makes the demo fail, naming the figure, at its end.
lcm_vs_offline=0
"$VIMOT_BIN/vimot-log-eval" "$VIMOT_LOG" --json "$out/lcm_summary.json" \
  --compare "$out/offline/summary.json" --tolerance 1e-6 > "$out/lcm_vs_offline.txt" 2>&1 || lcm_vs_offline=$?
sed 's/^/   /' "$out/lcm_vs_offline.txt"
finish() {
  echo "== input per process and channel (heartbeats' final counts; $out/input_report.txt):"
  local report_status=0
  "$here/scripts/demo_input_report.sh" "$out/sheriff.txt" "$VIMOT_LOG" > "$out/input_report.txt" 2>&1 || report_status=$?
  sed 's/^/   /' "$out/input_report.txt"
  if [ "$lcm_vs_offline" -ne 0 ]; then
    echo "demo: the LCM run differs from the offline run of the same seed (vimot-log-eval exit $lcm_vs_offline):" >&2
    grep -E 'tolerance|error' "$out/lcm_vs_offline.txt" | sed 's/^/   /' >&2 || true
  fi
  if [ "$report_status" -ne 0 ]; then
    echo "demo: input lost without being counted (NOT COUNTED, NO FINAL COUNT or LOG DIFFERS above)" >&2
    exit 5
  fi
  [ "$lcm_vs_offline" -eq 0 ] || exit 4
  exit 0
}
echo "   (offline run of the same scenario and seed: $out/offline.txt)"
if [ $pipeline = pixels ] || [ $pipeline = pixels-truthbox ]; then
  echo "== the same seed at feature level (the simulator's own tracks, no pixels), offline:"
  "$VIMOT_BIN/vimot-vio-eval" --sim-config "$VIMOT_CONFIG/$VIMOT_SIM_CONFIG" \
    --vins-config "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" --runs 1 --first-seed "$VIMOT_SEED" \
    --duration "$VIMOT_DURATION" --perturb-seed "${perturb_seed:-0}" --quiet > "$out/offline_features.txt" 2>&1 || true
  grep -E '^(seed|mean|pred)' "$out/offline_features.txt" | sed 's/^/   /'
fi
if [ $pipeline = pixels ]; then
  echo "== target box of the LCM run (TARGET_BOX vs TARGET_BOX_TRUTH):"
  "$VIMOT_BIN/vimot-log-eval" "$VIMOT_LOG" --state-channel NAV_STATE --target-channel TARGET_STATE \
    --own-target-frame --box-channel TARGET_BOX > "$out/lcm_box.txt" 2>&1 || true
  grep -E '^(box|target kept)' "$out/lcm_box.txt" | sed 's/^/   /'
fi
if [ $pipeline = mono_pixels ] || [ $pipeline = mono_segmented ]; then
  echo "== metric scale of the LCM run (SCALE_ESTIMATE, OBJECT_POSE_METRIC, OBJECT_STATE vs GROUND_TRUTH), and the offline run from pixels:"
  "$VIMOT_BIN/vimot-scale-eval" --sim-config "$VIMOT_CONFIG/$VIMOT_SIM_CONFIG" \
    --vins-config "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" --tracker-config "$VIMOT_CONFIG/object_tracker.yaml" \
    --scale-config "$VIMOT_CONFIG/scale_estimator.yaml" --runs 1 --first-seed "$VIMOT_SEED" \
    --perturb-seed "${perturb_seed:-0}" "${offline_args[@]}" --out "$out/offline_scale" --quiet > "$out/offline_scale.txt" 2>&1 || true
  grep -E '^(seed|mean)' "$out/offline_scale.txt" | sed 's/^/   /' || true
  scale_status=0
  "$VIMOT_BIN/vimot-log-eval" "$VIMOT_LOG" --scale-truth "$out/offline_scale/summary.json" --tolerance 1e-6 \
    > "$out/lcm_vs_offline_scale.txt" 2>&1 || scale_status=$?
  grep -E '^(scale|metric|filtered|compare|  (scale|accepted|last|object|filtered))' "$out/lcm_vs_offline_scale.txt" \
    | sed 's/^/   /' || true
  if [ "$scale_status" -ne 0 ] && [ "$lcm_vs_offline" -eq 0 ]; then
    lcm_vs_offline=$scale_status
    cat "$out/lcm_vs_offline_scale.txt" >> "$out/lcm_vs_offline.txt"
  fi
  echo "   (offline run: $out/offline_scale.txt)"
  echo "== log (images left out): $VIMOT_LOG"
  finish
fi
if [ $pipeline = mono ]; then
  echo "== metric scale of the LCM run (SCALE_ESTIMATE, OBJECT_POSE_METRIC, OBJECT_STATE vs GROUND_TRUTH), and the offline run:"
  "$VIMOT_BIN/vimot-scale-eval" --sim-config "$VIMOT_CONFIG/$VIMOT_SIM_CONFIG" \
    --vins-config "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" --tracker-config "$VIMOT_CONFIG/object_tracker.yaml" \
    --scale-config "$VIMOT_CONFIG/scale_estimator.yaml" --runs 1 --first-seed "$VIMOT_SEED" \
    --perturb-seed "${perturb_seed:-0}" --out "$out/offline_scale" --quiet > "$out/offline_scale.txt" 2>&1 || true
  "$VIMOT_BIN/vimot-log-eval" "$VIMOT_LOG" --scale-truth "$out/offline_scale/summary.json" \
    | grep -E '^(scale|metric|filtered|compare|  (scale|accepted|last|object|filtered))' | sed 's/^/   /'
  echo "   (offline run: $out/offline_scale.txt)"
  echo "== log: $VIMOT_LOG"
  echo "   replay: scripts/replay.sh $VIMOT_LOG [--offline]    watch: scripts/lcm-spy.sh"
  finish
fi
if [ "${VIMOT_TARGET_MODE:-skf}" = skf ]; then
  echo "== robot accuracy of the target filter (NAV_STATE, Schmidt-EKF: must equal VINS_STATE):"
else
  echo "== robot accuracy of the target filter (NAV_STATE, mode $VIMOT_TARGET_MODE: the target may move the robot):"
fi
"$VIMOT_BIN/vimot-log-eval" "$VIMOT_LOG" --state-channel NAV_STATE \
  --compare "$out/lcm_summary.json" | sed 's/^/   /'
echo "== target accuracy of the LCM run (TARGET_STATE vs GROUND_TRUTH), and the offline run:"
target_cfg="$VIMOT_CONFIG/target_filter.yaml"
# init.mode features: the filter's own target frame, compared through the fixed transform.
own_frame=""
if sed -n '/^  init:/,/^  [a-z_]*:/p' "$target_cfg" | grep -q '^    mode: *features'; then own_frame="--own-target-frame"; fi
target_eval() {  # the offline target run of this seed; $1: output name, then extra options
  local name=$1
  shift
  "$VIMOT_BIN/vimot-target-eval" --sim-config "$VIMOT_CONFIG/$VIMOT_SIM_CONFIG" \
    --vins-config "$VIMOT_CONFIG/$VIMOT_VINS_CONFIG" --target-config "$target_cfg" \
    --modes "${VIMOT_TARGET_MODE:-$(target_key mode)}" --representations "$(target_key representation)" \
    --sigmas "$(target_key sigma_t)" --no-vio-only --runs 1 --first-seed "$VIMOT_SEED" \
    --perturb-seed "${perturb_seed:-0}" "$@" --out "$out/$name" --quiet > "$out/$name.txt" 2>&1 || true
}
target_eval offline_target "${offline_args[@]}"
target_status=0
"$VIMOT_BIN/vimot-log-eval" "$VIMOT_LOG" --state-channel NAV_STATE --target-channel TARGET_STATE $own_frame \
  --compare-target "$out/offline_target/summary.json" --tolerance 1e-6 > "$out/lcm_vs_offline_target.txt" 2>&1 \
  || target_status=$?
grep -E '^(target|compare|  target|  robot)' "$out/lcm_vs_offline_target.txt" | sed 's/^/   /' || true
if [ "$target_status" -ne 0 ] && [ "$lcm_vs_offline" -eq 0 ]; then
  lcm_vs_offline=$target_status
  cat "$out/lcm_vs_offline_target.txt" >> "$out/lcm_vs_offline.txt"
fi
echo "   (offline target run: $out/offline_target.txt)"
if [ $pipeline = pixels ] || [ $pipeline = pixels-truthbox ]; then
  echo "== the same seed's target at feature level (the simulator's own tracks, no pixels), offline:"
  target_eval offline_target_features --duration "$VIMOT_DURATION"
  grep -E '^(\| (σ_t|[0-9])|Table|Average|  .*target estimate on)' "$out/offline_target_features.txt" \
    | sed 's/^ */   /'
  echo "   (from pixels: $out/offline_target.txt)"
  echo "== log (images and masks left out): $VIMOT_LOG"
  finish
fi
echo "== log: $VIMOT_LOG"
echo "   replay: scripts/replay.sh $VIMOT_LOG [--offline]    watch: scripts/lcm-spy.sh"
finish

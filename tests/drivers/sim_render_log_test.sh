#!/usr/bin/env bash
# vimot-sim --render --log: the same seed gives a byte-identical log; every
# message decodes; one image, mask and box per camera and frame (stereo paper:
# CAM_LEFT and CAM_RIGHT; mono: CAM_LEFT only); FEATURES only with
# --with-features.
# usage: sim_render_log_test.sh VIMOT_SIM VIMOT_LOG_SUMMARY CONFIG_DIR WORKDIR
set -euo pipefail
sim="$1"; summary="$2"; configs="$3"; work="$4"
mkdir -p "$work"
expect() {  # expect FILE CHANNEL TYPE COUNT
  grep -Eq "^$2 +vimot.$3 +$4 " "$1" || { cat "$1"; echo "FAIL: expected $4 $3 on $2 in $1"; exit 1; }
}
absent() {  # absent FILE CHANNEL
  if grep -Eq "^$2 " "$1"; then cat "$1"; echo "FAIL: $2 in $1"; exit 1; fi
}
# Paper: 1 s at 200 Hz IMU and 10 Hz stereo, both ends included.
"$sim" --config "$configs/sim_paper.yaml" --seed 3 --duration 1 --render --log "$work/a.lcm" --log-level warn
"$sim" --config "$configs/sim_paper.yaml" --seed 3 --duration 1 --render --log "$work/b.lcm" --log-level warn
cmp "$work/a.lcm" "$work/b.lcm" || { echo "FAIL: same seed, different bytes"; exit 1; }
"$summary" "$work/a.lcm" > "$work/paper.txt" || { cat "$work/paper.txt"; echo "FAIL: undecodable messages"; exit 1; }
expect "$work/paper.txt" IMU imu_t 201
expect "$work/paper.txt" GROUND_TRUTH ground_truth_t 201
expect "$work/paper.txt" CAM_LEFT image_t 11
expect "$work/paper.txt" CAM_RIGHT image_t 11
expect "$work/paper.txt" TARGET_MASK_TRUTH mask_t 22
expect "$work/paper.txt" TARGET_BOX_TRUTH target_box_t 22
absent "$work/paper.txt" FEATURES
"$sim" --config "$configs/sim_paper.yaml" --seed 3 --duration 1 --render --with-features --log "$work/f.lcm" \
  --log-level warn
"$summary" "$work/f.lcm" > "$work/features.txt"
expect "$work/features.txt" FEATURES features_t 11
expect "$work/features.txt" CAM_LEFT image_t 11
# Mono: 20 Hz, one camera.
"$sim" --config "$configs/sim_mono.yaml" --seed 3 --duration 1 --render --log "$work/m.lcm" --log-level warn
"$summary" "$work/m.lcm" > "$work/mono.txt" || { cat "$work/mono.txt"; echo "FAIL: undecodable messages"; exit 1; }
expect "$work/mono.txt" CAM_LEFT image_t 21
expect "$work/mono.txt" TARGET_MASK_TRUTH mask_t 21
expect "$work/mono.txt" TARGET_BOX_TRUTH target_box_t 21
absent "$work/mono.txt" CAM_RIGHT
echo "PASS"

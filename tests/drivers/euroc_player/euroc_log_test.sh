#!/usr/bin/env bash
# vimot-euroc-player end to end: --help and a missing folder exit cleanly
# (always); on the real slice (VIMOT_DATA_DIR, else skip with 77) --log
# writes the same bytes twice and every message decodes, with the expected
# count per channel.
# usage: euroc_log_test.sh VIMOT_EUROC_PLAYER VIMOT_LOG_SUMMARY WORKDIR
set -euo pipefail
player="$1"; summary="$2"; work="$3"
mkdir -p "$work"
"$player" --help > "$work/help.txt" || { echo "FAIL: --help exit code"; exit 1; }
grep -q -- "--dataset DIR" "$work/help.txt" || { echo "FAIL: --help does not list --dataset"; exit 1; }
set +e
"$player" --dataset "$work/no_such_folder" --log "$work/none.lcm" --log-level warn 2> "$work/missing.txt"
rc=$?
set -e
[ "$rc" -eq 1 ] || { echo "FAIL: missing folder exit code $rc, expected 1"; cat "$work/missing.txt"; exit 1; }
grep -q "no_such_folder' does not exist" "$work/missing.txt" || { echo "FAIL: unclear error"; cat "$work/missing.txt"; exit 1; }

if [ -z "${VIMOT_DATA_DIR:-}" ] || [ ! -d "$VIMOT_DATA_DIR/euroc_v101_micro/mav0" ]; then
  echo "VIMOT_DATA_DIR unset or without euroc_v101_micro: skipping the slice part"
  exit 77
fi
slice="$VIMOT_DATA_DIR/euroc_v101_micro"
for run in a b; do
  "$player" --dataset "$slice" --groundtruth "$slice/groundtruth/V1_01_easy.csv" --log "$work/$run.lcm" \
    --log-level warn
done
cmp "$work/a.lcm" "$work/b.lcm" || { echo "FAIL: two runs, different bytes"; exit 1; }
"$summary" "$work/a.lcm" > "$work/summary.txt" || { cat "$work/summary.txt"; echo "FAIL: undecodable messages"; exit 1; }
cat "$work/summary.txt"
# 95 stereo pairs; 4.7 s of IMU at 200 Hz, both ends included; truth at 20 Hz.
grep -Eq '^IMU +vimot.imu_t +941 ' "$work/summary.txt" || { echo "FAIL: expected 941 IMU"; exit 1; }
grep -Eq '^CAM_LEFT +vimot.image_t +95 ' "$work/summary.txt" || { echo "FAIL: expected 95 CAM_LEFT"; exit 1; }
grep -Eq '^CAM_RIGHT +vimot.image_t +95 ' "$work/summary.txt" || { echo "FAIL: expected 95 CAM_RIGHT"; exit 1; }
grep -Eq '^GROUND_TRUTH +vimot.ground_truth_t +95 ' "$work/summary.txt" || { echo "FAIL: expected 95 GROUND_TRUTH"; exit 1; }
rm -f "$work"/a.lcm "$work"/b.lcm
echo "PASS"

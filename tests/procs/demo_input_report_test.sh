#!/usr/bin/env bash
# scripts/demo_input_report.sh on hand-made sheriff output of the pixels
# chain: the rendering simulator says "0 on FEATURES" and the feature
# tracker publishes them, so FEATURES count as the tracker's 301; a
# consumer that received 300 and counted none lost is NOT COUNTED (1).
set -euo pipefail
report="$1"
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
write() {  # $1: FEATURES received by vins
  cat > "$dir/sheriff.txt" <<TXT
[sheriff] started 'feature_tracker' (pid 11): vimot-feature-tracker
[feature_tracker] 2026-01-01 00:00:00.000 [feature_tracker] INFO: started (pid 11)
[sheriff] started 'vins' (pid 12): vimot-vins
[vins] 2026-01-01 00:00:00.000 [vins] INFO: started (pid 12)
[sim] 2026-01-01 00:00:30.000 [vimot-sim] INFO: done: 6001 on IMU, 0 on FEATURES, 6001 on GROUND_TRUTH, 602 rendered images (+ masks, boxes)
[feature_tracker] 2026-01-01 00:00:31.000 [feature_tracker] INFO: stopping: in 1204, out 301, decode errors 0, dropped 0, lost 0, errors 0, in CAM_LEFT 301, in CAM_RIGHT 301, out FEATURES 301, cpu 1 s
[vins] 2026-01-01 00:00:32.000 [vins] INFO: stopping: in 12302, out 900, decode errors 0, dropped 0, lost 0, errors 0, in IMU 6001, in FEATURES $1, in GROUND_TRUTH 6001, out VINS_STATE 900, cpu 1 s
TXT
}
write 301
out=$(bash "$report" "$dir/sheriff.txt") || { echo "exact counts reported as not exact:"; echo "$out"; exit 1; }
grep -q "FEATURES          published    301  received    301  counted lost 0" <<< "$out" || { echo "$out"; exit 1; }
write 300
status=0
out=$(bash "$report" "$dir/sheriff.txt") || status=$?
[ $status -eq 1 ] || { echo "a missed message passed (exit $status):"; echo "$out"; exit 1; }
grep -q "FEATURES          published    301  received    300  counted lost 0  NOT COUNTED: 1 missed" <<< "$out" || { echo "$out"; exit 1; }
echo "demo_input_report_test: ok"

#!/usr/bin/env bash
# vimot-sim --log: the same seed gives a byte-identical log, another seed a
# different one, and every message in it decodes with the expected count.
# usage: sim_log_test.sh VIMOT_SIM VIMOT_LOG_SUMMARY CONFIG WORKDIR
set -euo pipefail
sim="$1"; summary="$2"; config="$3"; work="$4"
mkdir -p "$work"
"$sim" --config "$config" --seed 3 --duration 10 --log "$work/a.lcm" --log-level warn
"$sim" --config "$config" --seed 3 --duration 10 --log "$work/b.lcm" --log-level warn
"$sim" --config "$config" --seed 4 --duration 10 --log "$work/c.lcm" --log-level warn
cmp "$work/a.lcm" "$work/b.lcm" || { echo "FAIL: same seed, different bytes"; exit 1; }
if cmp -s "$work/a.lcm" "$work/c.lcm"; then echo "FAIL: seeds 3 and 4 gave identical logs"; exit 1; fi
"$summary" "$work/a.lcm" > "$work/summary.txt" || { cat "$work/summary.txt"; echo "FAIL: undecodable messages"; exit 1; }
cat "$work/summary.txt"
# 10 s at 200 Hz and 10 Hz, both ends included: 2001 IMU samples, 101 frames.
grep -Eq '^IMU +vimot.imu_t +2001 ' "$work/summary.txt" || { echo "FAIL: expected 2001 IMU messages"; exit 1; }
grep -Eq '^GROUND_TRUTH +vimot.ground_truth_t +2001 ' "$work/summary.txt" || { echo "FAIL: expected 2001 GROUND_TRUTH"; exit 1; }
grep -Eq '^FEATURES +vimot.features_t +101 ' "$work/summary.txt" || { echo "FAIL: expected 101 FEATURES"; exit 1; }
# Event time = utime: a log "recorded at" real time, which scripts/replay.sh relies on.
[ "$("$summary" --speed "$work/a.lcm")" = 1 ] || { echo "FAIL: vimot-sim --log must read as recorded at 1x"; exit 1; }
# --outage-at 5 --outage-length 1: nothing with utime in [5 s, 6 s) after the
# start, hand count: 200 IMU samples and truths, 10 frames fewer, and one
# silence of 1.005 s (IMU) / 1.1 s (frames) in each stream.
"$sim" --config "$config" --seed 3 --duration 10 --outage-at 5 --outage-length 1 --log "$work/d.lcm" --log-level warn
"$summary" --gaps "$work/d.lcm" > "$work/outage.txt"
cat "$work/outage.txt"
grep -Eq '^IMU +vimot.imu_t +1801 .* 1\.005 ' "$work/outage.txt" || { echo "FAIL: outage: expected 1801 IMU, gap 1.005 s"; exit 1; }
grep -Eq '^GROUND_TRUTH +vimot.ground_truth_t +1801 ' "$work/outage.txt" || { echo "FAIL: outage: expected 1801 GROUND_TRUTH"; exit 1; }
grep -Eq '^FEATURES +vimot.features_t +91 .* 1\.100 ' "$work/outage.txt" || { echo "FAIL: outage: expected 91 FEATURES, gap 1.1 s"; exit 1; }
for bad in "--outage-at 5" "--outage-at 5 --outage-length 0" "--outage-at -1 --outage-length 1" "--outage-at 11 --outage-length 1"; do
  # shellcheck disable=SC2086
  if "$sim" --config "$config" --duration 10 $bad --log "$work/e.lcm" --log-level warn 2> "$work/err.txt"; then
    echo "FAIL: vimot-sim accepted $bad"; exit 1
  fi
  grep -q "outage" "$work/err.txt" || { cat "$work/err.txt"; echo "FAIL: no clear error for $bad"; exit 1; }
done
echo "PASS"

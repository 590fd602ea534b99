#!/usr/bin/env bash
# vimot-sim --clock-file: a restart within the run goes on with the first
# start's schedule, skipping what fell due while it was down (as a real
# sensor); a start after the run has ended is a fresh run; with --log the
# option is refused. Publishes on a private URL (nothing needs to listen).
# usage: sim_clock_file_test.sh VIMOT_SIM CONFIG WORKDIR
set -euo pipefail
sim="$1"; config="$2"; work="$3"
rm -rf "$work"; mkdir -p "$work"
export LCM_DEFAULT_URL='udpm://239.255.76.67:7696?ttl=0'
run() { "$sim" --config "$config" --duration 4 --speed 2 --clock-file "$work/clock" "$@"; }
imu_sent() { sed -n 's/.*done: \([0-9]*\) on IMU.*/\1/p' "$1"; }

run > "$work/first.txt" 2>&1 &
pid=$!
sleep 1
kill -9 $pid
wait $pid 2>/dev/null || true
[ -s "$work/clock" ] || { echo "FAIL: no clock file written"; exit 1; }
run > "$work/restart.txt" 2>&1
cat "$work/restart.txt"
grep -q "restarted .* s into the run" "$work/restart.txt" || { echo "FAIL: the restart did not resume the run"; exit 1; }
# 4 s of data at 200 Hz is 801 samples; killed after ~1 s wall (2 s of data) the
# restart sends only what is due from then on.
n=$(imu_sent "$work/restart.txt")
[ -n "$n" ] && [ "$n" -gt 0 ] && [ "$n" -lt 600 ] || { echo "FAIL: the restart sent $n IMU samples (expected 1..599)"; exit 1; }
# The run (2 s of wall time) has ended: the next start is a fresh run.
run > "$work/fresh.txt" 2>&1
if grep -q "restarted" "$work/fresh.txt"; then echo "FAIL: a start after the run's end resumed it"; exit 1; fi
[ "$(imu_sent "$work/fresh.txt")" = 801 ] || { echo "FAIL: a fresh run must send all 801 IMU samples"; exit 1; }
if "$sim" --config "$config" --duration 1 --log "$work/x.lcm" --clock-file "$work/clock" > "$work/log.txt" 2>&1; then
  echo "FAIL: --clock-file with --log was accepted"; exit 1
fi
grep -q "clock-file needs a paced run" "$work/log.txt" || { cat "$work/log.txt"; echo "FAIL: no clear error"; exit 1; }
echo "PASS"

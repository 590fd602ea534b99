#!/usr/bin/env bash
# The two-host layout (sheriff_configs/two_hosts.pmd) on one machine: two
# network namespaces joined by a veth pair stand for the vehicle and the
# ground station, each runs a vimot-deputy named after it, LCM multicast
# (ttl=1) crosses between them, and vimot-sheriff --lcm (on the ground
# station) drives both by procman's protocol. The ground station's logger
# must record the vehicle's estimates. Needs root (ip netns).
#   scripts/two_hosts_netns.sh [SECONDS]   run length, default 30
# Environment: VIMOT_BUILD_DIR (default build), VIMOT_OUT (default
# out/two-hosts-<date>), VIMOT_SIM_CONFIG, VIMOT_VINS_CONFIG, VIMOT_SPEED,
# VIMOT_SEED as for scripts/demo.sh.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIMOT_BUILD_DIR:-$here/build}"
case "${1:-}" in
  -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
esac
seconds="${1:-30}"
for exe in vimot-deputy vimot-sheriff vimot-sim vimot-vins vimot-target-filter vimot-log-summary; do
  [ -x "$build/bin/$exe" ] || { echo "two_hosts_netns: $build/bin/$exe missing; build first" >&2; exit 1; }
done

out="${VIMOT_OUT:-$here/out/two-hosts-$(date +%Y%m%d-%H%M%S)}"
mkdir -p "$out"
# Names unique to this run, so parallel runs do not collide.
vehicle="vimot_veh_$$"
ground="vimot_gnd_$$"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
  ip netns del "$vehicle" 2>/dev/null || true
  ip netns del "$ground" 2>/dev/null || true
}
trap cleanup EXIT

ip netns add "$vehicle"
ip netns add "$ground"
ip link add "veth_v$$" type veth peer name "veth_g$$"
ip link set "veth_v$$" netns "$vehicle"
ip link set "veth_g$$" netns "$ground"
setup() {  # namespace device address
  ip -n "$1" link set lo up
  ip -n "$1" addr add "$3/24" dev "$2"
  ip -n "$1" link set "$2" up
  ip -n "$1" route add 224.0.0.0/4 dev "$2"
}
setup "$vehicle" "veth_v$$" 10.231.0.1
setup "$ground" "veth_g$$" 10.231.0.2

export LCM_DEFAULT_URL="udpm://239.255.76.67:7667?ttl=1"
export VIMOT_BIN="$build/bin" VIMOT_CONFIG="$here/config"
export VIMOT_SIM_CONFIG="${VIMOT_SIM_CONFIG:-sim_paper.yaml}"
export VIMOT_VINS_CONFIG="${VIMOT_VINS_CONFIG:-vins.yaml}"
export VIMOT_SPEED="${VIMOT_SPEED:-4}" VIMOT_SEED="${VIMOT_SEED:-1}"
export VIMOT_LOG="$out/ground.lcmlog"

ip netns exec "$vehicle" "$build/bin/vimot-deputy" --name vehicle > "$out/deputy_vehicle.txt" 2>&1 &
pids+=($!)
ip netns exec "$ground" "$build/bin/vimot-deputy" --name ground > "$out/deputy_ground.txt" 2>&1 &
pids+=($!)
sleep 1
echo "== sheriff on the ground station, $seconds s (output in $out/sheriff.txt)"
set +e
ip netns exec "$ground" "$build/bin/vimot-sheriff" --lcm --script run --duration "$seconds" \
  "$here/sheriff_configs/two_hosts.pmd" > "$out/sheriff.txt" 2>&1
status=$?
set -e
grep '^\[sheriff\]' "$out/sheriff.txt" | sed 's/^/   /'
[ $status -eq 0 ] || { echo "two_hosts_netns: sheriff exited with $status" >&2; exit $status; }
echo "== recorded on the ground station:"
"$build/bin/vimot-log-summary" "$VIMOT_LOG" | sed 's/^/   /'
for channel in VINS_STATE TARGET_STATE; do
  "$build/bin/vimot-log-summary" "$VIMOT_LOG" | grep -q "^$channel " ||
    { echo "two_hosts_netns: the ground station did not receive $channel" >&2; exit 1; }
done
echo "== the ground station received the vehicle's estimates"

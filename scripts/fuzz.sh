#!/usr/bin/env bash
# Builds a libFuzzer target (clang, -DVIMOT_FUZZ=ON, its own build folder),
# runs it for N seconds at the lowest CPU priority, then reports the line and
# branch coverage of the parser sources reached by the corpus.
#   scripts/fuzz.sh [SECONDS] [TARGET] [LIBFUZZER OPTIONS...]   (defaults: 60, fuzz_mip_parser)
# e.g. scripts/fuzz.sh 1800 fuzz_mip_parser -len_control=0   (long inputs from the start)
# Seed corpus for fuzz_mip_parser: the real MIP recording in
# $VIMOT_DATA_DIR/mip cut into 4 KiB slices (small seeds run faster than the
# whole 369 KB file; together they hold every byte of it). The corpus grows
# in build-fuzz/corpus/<target>; crashes land in build-fuzz/artifacts/.
set -euo pipefail

SECONDS_TO_RUN=${1:-60}
TARGET=${2:-fuzz_mip_parser}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${VIMOT_FUZZ_BUILD:-$ROOT/build-fuzz}

if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ not found (apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi

if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  CC=clang CXX=clang++ cmake -S "$ROOT" -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DVIMOT_FUZZ=ON -DBUILD_TESTING=OFF
fi
nice -n 19 cmake --build "$BUILD" -j2 --target "$TARGET" "${TARGET}_cov"

CORPUS=$BUILD/corpus/$TARGET
mkdir -p "$CORPUS" "$BUILD/artifacts"
RECORDING=${VIMOT_DATA_DIR:-}/mip/mip_data.bin
if [ "$TARGET" = fuzz_mip_parser ] && [ -f "$RECORDING" ]; then
  if [ -z "$(ls "$CORPUS" | grep '^slice_')" ]; then
    split -b 4096 -d -a 3 "$RECORDING" "$CORPUS/slice_"
  fi
  # Seeds for the reframed mode (first byte >= 0x80): the recording's
  # packets as (set, length, payload) records, 50 per seed.
  if [ -z "$(ls "$CORPUS" | grep '^reframed_')" ]; then
    python3 - "$RECORDING" "$CORPUS" <<'PY'
import sys
data = open(sys.argv[1], "rb").read()
records, i = [], 0
while i + 4 <= len(data) and data[i:i + 2] == b"\x75\x65":
    n = data[i + 3]
    records.append(data[i + 2:i + 4 + n])
    i += 6 + n
for k in range(0, len(records), 50):
    with open(f"{sys.argv[2]}/reframed_{k // 50:03d}", "wb") as f:
        f.write(bytes([0x80 | (k // 50 % 0x80)]) + b"".join(records[k:k + 50]))
PY
  fi
elif [ "$TARGET" = fuzz_mip_parser ] && [ -z "$(ls -A "$CORPUS")" ]; then
  echo "fuzz.sh: no seed corpus (set VIMOT_DATA_DIR to the shared data folder); starting empty" >&2
fi

DICT=()
if [ "$TARGET" = fuzz_mip_parser ]; then DICT=(-dict="$ROOT/drivers/imu_mip/fuzz_mip_parser.dict"); fi

nice -n 19 "$BUILD/bin/$TARGET" "$CORPUS" "${DICT[@]}" -max_len=1048576 -max_total_time="$SECONDS_TO_RUN" \
  -print_final_stats=1 -artifact_prefix="$BUILD/artifacts/" "${@:3}"

# Coverage of the corpus: the uninstrumented-by-sanitizer twin runs every
# input once and writes a profile.
if command -v llvm-profdata >/dev/null && command -v llvm-cov >/dev/null; then
  PROFILE=$BUILD/$TARGET.profraw
  LLVM_PROFILE_FILE=$PROFILE nice -n 19 "$BUILD/bin/${TARGET}_cov" "$CORPUS" -runs=0 >/dev/null 2>&1
  llvm-profdata merge -sparse "$PROFILE" -o "$BUILD/$TARGET.profdata"
  llvm-cov report "$BUILD/bin/${TARGET}_cov" -instr-profile="$BUILD/$TARGET.profdata" \
    "$ROOT"/drivers/imu_mip/mip_protocol.cc "$ROOT"/drivers/imu_mip/mip_parser.cc "$ROOT"/drivers/imu_mip/mip_messages.cc
fi

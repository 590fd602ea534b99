#!/usr/bin/env bash
# The README's test command: install what is missing, build, run every test.
# Tests that need ../shared/data find it through VIMOT_DATA_DIR; without it
# they skip and say so.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIMOT_BUILD_DIR:-$here/build}"
if [ -z "${VIMOT_DATA_DIR:-}" ] && [ -d "$here/../shared/data" ]; then
  export VIMOT_DATA_DIR="$(cd "$here/../shared/data" && pwd)"
fi
"$here/scripts/build.sh"
cd "$build"
ctest --output-on-failure -j "$(nproc)" "$@"

#!/usr/bin/env bash
# Configures and builds vimot (Release) into ${VIMOT_BUILD_DIR:-build}.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${VIMOT_BUILD_DIR:-$here/build}"
"$here/scripts/install_deps.sh"
cmake -S "$here" -B "$build" -DCMAKE_BUILD_TYPE="${CMAKE_BUILD_TYPE:-Release}" >/dev/null
cmake --build "$build" -j "$(nproc)"

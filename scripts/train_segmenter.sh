#!/usr/bin/env bash
# Reproduces the shipped segmentation network (docs/segmenter.md): renders
# the training set (seed 1) and the held-out test set (seed 1001), trains the
# UNet on one thread, exports config/models/segmenter_unet.onnx, the C++
# cross-check reference (tests/segmentation/data/) and the held-out figures
# (config/models/segmenter_unet_metrics.json).
# Needs a build (vimot-segmentation-data) and, for development only, Debian's
# python3-torch python3-onnx python3-pil (not in scripts/install_deps.sh).
# Usage: scripts/train_segmenter.sh [BUILD_DIR] [WORK_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
work=${2:-/tmp/vimot_segmentation_data}
cmake --build "$build" -j2 --target vimot-segmentation-data
rm -rf "$work" && mkdir -p "$work/train" "$work/test"
"$build/bin/vimot-segmentation-data" --out "$work/train" --runs 60 --frames 14 --seed 1
"$build/bin/vimot-segmentation-data" --out "$work/test" --runs 16 --frames 8 --seed 1001
# The system python: Debian's torch is not visible to a pyenv/venv python.
/usr/bin/python3 scripts/train_segmenter.py --train "$work/train" --test "$work/test" \
  --out config/models/segmenter_unet.onnx --reference tests/segmentation/data \
  --metrics config/models/segmenter_unet_metrics.json 

#!/usr/bin/env bash
# Quick start, command 1: install, build (Release) and run the default scene with `orrery run`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
mkdir -p results
build/bin/orrery run models/scenes/default.yaml -o results/default.h5
build/bin/orrery inspect results/default.h5 | head -n 25

#!/usr/bin/env bash
# Installs the dependencies (Debian 12 packages) and builds Orrery in Release into ./build.
# Usage: tools/build.sh [extra cmake configure arguments]
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/install_deps.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "$@" >/dev/null
cmake --build build -j "$jobs"

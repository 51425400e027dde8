#!/usr/bin/env bash
# Quick start, command 2: install, build (Release) and run the whole test suite with ctest.
# Usage: tools/run_tests.sh [extra cmake configure arguments, e.g. -DORRERY_WERROR=ON]
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh "$@"
jobs=$(nproc 2>/dev/null || echo 2)
cd build
ctest --output-on-failure -j "$jobs" --timeout 1200

#!/usr/bin/env bash
# Builds test suites with AddressSanitizer + UndefinedBehaviorSanitizer in build-asan/ and runs
# them; any finding stops its test program (halt_on_error, -fno-sanitize-recover) and fails the
# script. Optimized (-O1) with debug info and Eigen's assertions on. Without -Werror: GCC 12
# reports Eigen's aliasing checks as maybe-uninitialized once instrumented (false positives; the
# Release build in CI is the one with -Werror).
# Usage: tools/run_sanitized_tests.sh [SUITE...]   suites: mbd flex contact models import tools
#   default: the suites CI runs (see SUITES below: chosen so that .ci/run stays within 90 minutes
#   on a fresh 2-core machine).
set -euo pipefail
cd "$(dirname "$0")/.."
SUITES=(mbd contact)
suites=("$@")
[ ${#suites[@]} -gt 0 ] || suites=("${SUITES[@]}")
build=build-asan
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g" \
      -DORRERY_SANITIZE=address,undefined -DORRERY_BUILD_BENCHMARKS=OFF -DORRERY_WERROR=OFF >/dev/null
targets=()
for s in "${suites[@]}"; do targets+=("orrery_${s}_tests"); done
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

# Every finding is fatal and reported with a stack trace; leaks count as findings.
export ASAN_OPTIONS="halt_on_error=1:abort_on_error=0:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
cd "$build"
labels=$(IFS='|'; echo "${suites[*]}")
ctest --output-on-failure --no-tests=error -j "$jobs" -L "^(${labels})\$"

#!/usr/bin/env bash
# Fuzzes the file readers for a short while: builds the libFuzzer programs (tools/fuzz/, clang 14
# with AddressSanitizer and UndefinedBehaviorSanitizer; Debian packages clang-14 and
# libfuzzer-14-dev) in build-fuzz/, then runs each for SECONDS (default 10) from its seed corpus:
# tools/fuzz/corpus/<reader>/, the inputs that once broke it (tests/fuzz_regressions/<reader>/),
# and for the scene reader the ready scenes of models/scenes/. A crash, a sanitizer report, a
# leak, an input slower than 20 s or above 2 GB of memory fails the run; the input is saved as
# build-fuzz/crashes/<reader>-crash-<hash>: fix the reader, then copy the input into
# tests/fuzz_regressions/<reader>/ so the normal test suite replays it
# (tests/tools/fuzz_regression_test.cpp).
#
#   bash tools/fuzz/run_fuzz.sh [SECONDS] [READER ...]     # readers: stl obj msh inp matrix scene
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-10}
shift || true
readers=("$@")
if [ ${#readers[@]} -eq 0 ]; then readers=(stl obj msh inp matrix scene); fi

for tool in clang-14 clang++-14; do
  command -v "$tool" > /dev/null || { echo "run_fuzz: $tool not found: install Debian's clang-14 and libfuzzer-14-dev"; exit 1; }
done

# Build (a separate directory: every source is instrumented; -O1 with assertions on)
build=build-fuzz
CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Fuzz -DCMAKE_CXX_FLAGS_FUZZ="-O1" -DORRERY_FUZZ=ON \
  -DORRERY_BUILD_TESTS=OFF -DORRERY_BUILD_BENCHMARKS=OFF > /dev/null
targets=()
for r in "${readers[@]}"; do targets+=("fuzz_$r"); done
jobs=$(nproc 2>/dev/null || echo 2)
cmake --build "$build" -j "$jobs" --target "${targets[@]}"

# Run each fuzzer from a fresh copy of its seeds
mkdir -p "$build/crashes"
status=0
for r in "${readers[@]}"; do
  corpus="$build/corpus/$r"
  rm -rf "$corpus"
  mkdir -p "$corpus"
  cp tools/fuzz/corpus/"$r"/* "$corpus"/ 2> /dev/null || true
  cp tests/fuzz_regressions/"$r"/* "$corpus"/ 2> /dev/null || true
  if [ "$r" = scene ]; then
    cp models/scenes/pendulum.yaml models/scenes/slider_crank.yaml models/scenes/lin_parker_1999_n3.yaml "$corpus"/
  fi
  echo "run_fuzz: $r for ${seconds} s"
  if ! "$build/bin/fuzz_$r" "$corpus" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 -max_len=8192 \
      -artifact_prefix="$build/crashes/$r-" -print_final_stats=1 > "$build/fuzz_$r.log" 2>&1; then
    echo "run_fuzz: $r FAILED; the end of its log ($build/fuzz_$r.log):"
    tail -n 40 "$build/fuzz_$r.log"
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::peak_rss_mb" "$build/fuzz_$r.log" | tr '\n' ' '
    echo
  fi
done
exit $status

#!/usr/bin/env bash
# Installs a built tree into a scratch prefix and builds and runs tools/package_example/ against
# it twice: as a CMake project (find_package(Orrery)) and with pkg-config (orrery.pc).
# Usage: tools/check_package.sh [build dir (default: build)]
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" >/dev/null
echo "check_package: installed $(find "$prefix/include" -name '*.h' | wc -l) headers," \
     "$(ls "$prefix"/lib*/liborrery_*.a "$prefix"/lib/*/liborrery_*.a 2>/dev/null | wc -l) libraries"

# CMake: the example's own CMakeLists.txt, configured outside the source tree.
cp -r tools/package_example "$work/example"
cmake -S "$work/example" -B "$work/example-build" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/example-build" >/dev/null
"$work/example-build/pendulum"

# pkg-config: the same program compiled by hand.
pc_dir=$(dirname "$(find "$prefix" -name orrery.pc | head -1)")
flags=$(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags --libs orrery)
# shellcheck disable=SC2086
g++ -std=c++20 -O1 "$work/example/main.cpp" -o "$work/pendulum_pc" $flags
"$work/pendulum_pc" | sed 's/^/pkg-config build: /'
# Every installed header compiles with only the package's flags (no private dependency needed).
(cd "$prefix/include" && find . -name '*.h' | sort | sed 's|^\./\(.*\)|#include "\1"|') \
  > "$work/all_headers.cpp"
# shellcheck disable=SC2086
g++ -std=c++20 -fsyntax-only "$work/all_headers.cpp" $(PKG_CONFIG_PATH=$pc_dir pkg-config --cflags orrery)
echo "check_package: OK (all $(wc -l < "$work/all_headers.cpp") installed headers compile together)"

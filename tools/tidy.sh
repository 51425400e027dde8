#!/usr/bin/env bash
# Runs clang-tidy (.clang-tidy: bug-finding checks) over the sources of the given folders, using
# the compile commands of a configured build (CMAKE_EXPORT_COMPILE_COMMANDS is on).
# Usage: tools/tidy.sh [-b BUILD_DIR] [FOLDER...]     default: -b build mbd flex
#   prints the findings and a count per check; exit 1 if there are any.
set -euo pipefail
cd "$(dirname "$0")/.."
build=build
if [ "${1:-}" = "-b" ]; then build=$2; shift 2; fi
folders=("$@")
[ ${#folders[@]} -gt 0 ] || folders=(mbd flex)
command -v run-clang-tidy >/dev/null || {
  echo "tidy.sh: run-clang-tidy not found (Debian package clang-tidy)" >&2; exit 2; }
[ -f "$build/compile_commands.json" ] || {
  echo "tidy.sh: $build/compile_commands.json missing: configure first (cmake -S . -B $build)" >&2
  exit 2; }
files=()
for f in "${folders[@]}"; do files+=("$PWD/$f/"); done
regex=$(printf '%s|' "${files[@]}")
log=$(mktemp)
trap 'rm -f "$log"' EXIT
# GCC-only flags in the compile commands are dropped for clang.
run-clang-tidy -quiet -p "$build" -j "$(nproc)" -extra-arg=-Wno-unknown-warning-option \
  "(${regex%|})[^/]+\.cpp$" >"$log" 2>&1 || true
grep -E "^/.*(warning|error):" "$log" | sort -u > "$log.findings" || true
cat "$log.findings"
n=$(wc -l < "$log.findings")
if [ "$n" -gt 0 ]; then
  echo "tidy.sh: $n findings in ${folders[*]}:"
  sed -E 's/.*\[([a-z0-9.,-]+)\]$/\1/' "$log.findings" | sort | uniq -c | sort -rn
  rm -f "$log.findings"
  exit 1
fi
rm -f "$log.findings"
echo "tidy.sh: no findings in ${folders[*]}"

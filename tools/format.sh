#!/usr/bin/env bash
# Checks the formatting (.clang-format) of the C++ lines changed since a base commit: the lines
# you touched, not the whole tree (files are formatted as they are edited, never in one sweep).
# Usage: tools/format.sh [--fix] [BASE]     BASE: default `main` (or HEAD~1 on main itself)
#   exit 0: the changed lines are formatted;  1: they are not (the diff is printed);
#   --fix rewrites the changed lines in the working tree instead.
set -euo pipefail
cd "$(dirname "$0")/.."
command -v git-clang-format >/dev/null || {
  echo "format.sh: git-clang-format not found (Debian package clang-format)" >&2; exit 2; }
fix=0
if [ "${1:-}" = "--fix" ]; then fix=1; shift; fi
base=${1:-main}
git rev-parse --verify -q "$base" >/dev/null || { echo "format.sh: no commit '$base'" >&2; exit 2; }
base=$(git merge-base "$base" HEAD)
# On the base itself with nothing changed (e.g. CI on main): check the last commit.
if [ "$base" = "$(git rev-parse HEAD)" ] && git diff --quiet HEAD; then base=HEAD~1; fi
folders=(mbd flex contact models import tools tests)
if [ $fix -eq 1 ]; then
  git clang-format --force --extensions h,cpp "$base" -- "${folders[@]}" || true
  exit 0
fi
out=$(git clang-format --diff --extensions h,cpp "$base" -- "${folders[@]}" || true)
if [ -z "$out" ] || echo "$out" | grep -q "^no modified files\|did not modify any files"; then
  echo "format.sh: the lines changed since $base are formatted"
  exit 0
fi
echo "$out"
echo "format.sh: the lines above, changed since $base, are not formatted (tools/format.sh --fix)" >&2
exit 1

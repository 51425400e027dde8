#!/usr/bin/env bash
# Quick start, command 1: install the dependencies, build (Release) and run the seed 003 fault
# study (flexible planet 1 with a broken tooth against its healthy twin, docs/fault_study.md) into
# results/seed003_fault_study; the summary is printed at the end. Extra arguments go to
# `orrery fault-study` (e.g. --force to replace an earlier study's results).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
mkdir -p results
build/bin/orrery fault-study models/scenes/seed003_flexible_broken_tooth.yaml -o results/seed003_fault_study "$@"

#!/usr/bin/env bash
# Stability at the extremes (issue 16, docs/extremes.md): runs every study
# models/studies/extremes_*.yaml with `orrery study` into results/studies/<name> (a killed sweep
# resumes), then checks each run against its oracle (tools/extremes/check_extremes.py) and
# writes the outcome table to results/studies/extremes.md. Exit status 1 when a run FAILS (a
# check that fails without a warning, a stop without time and element, a crash).
#   bash tools/run_extremes.sh            # build/bin/orrery, all cores
#   bash tools/run_extremes.sh -j 1       # extra arguments go to every `orrery study`
set -euo pipefail
cd "$(dirname "$0")/.."
orrery=${ORRERY:-build/bin/orrery}
[ -x "$orrery" ] || { echo "run_extremes.sh: $orrery not found; build first (bash tools/build.sh)" >&2; exit 1; }
command -v python3 >/dev/null || { echo "run_extremes.sh: python3 not found (Debian package python3)" >&2; exit 1; }
for study in models/studies/extremes_*.yaml; do
  name=$(basename "$study" .yaml)
  echo "== $name" >&2
  "$orrery" study "$study" -o "results/studies/$name" "$@"
done
python3 tools/extremes/check_extremes.py results/studies | tee results/studies/extremes.md

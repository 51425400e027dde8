#!/usr/bin/env bash
# The trade study (docs/tradeoff.md): runs the studies of models/studies/tradeoff/ (seed 003
# healthy and broken tooth at three mesh models, seed 002's ramp, the flexible reference's refinement) into results/studies/tradeoff/,
# then tools/plot/tradeoff_plot.py, which writes docs/images/tradeoff_*.png and the table of
# docs/tradeoff.md (between its "tradeoff-table" markers).
#
#   bash tools/run_tradeoff.sh                 # all of it (37 min of CPU, ~20 min on 2 idle cores)
#   JOBS=1 bash tools/run_tradeoff.sh          # one run at a time (default 2)
#   bash tools/run_tradeoff.sh --plots-only    # tables and plots from the studies already run
#
# A killed run resumes where it stopped (finished runs are not redone, docs/studies.md). The runs
# are started at `nice -n 10`; their CPU time (user + system) is the cost the plots show, since
# wall time on a shared machine includes waiting for a core.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${JOBS:-2}
orrery=build/bin/orrery
out=results/studies/tradeoff
studies=(seed003_lumped_healthy seed003_lumped_broken_tooth seed002_alpha1_ramp
         seed003_contact_healthy seed003_contact_broken_tooth
         seed003_flexible_healthy seed003_flexible_broken_tooth
         seed003_flexible_healthy_refinement)

if [[ "${1:-}" != "--plots-only" ]]; then
  if [[ ! -x "$orrery" ]]; then
    bash tools/build.sh
  fi
  mkdir -p "$out"
  # The reduced planets of the modes axis, healthy and broken (a scene makes a missing one on its
  # first load; made here once, so that parallel runs never write the same file)
  for n in 5 10 50 100 200; do
    for scene in seed003_flexible_healthy seed003_flexible_broken_tooth; do
      [[ $n == 200 && $scene == seed003_flexible_broken_tooth ]] && continue  # healthy only
      nice -n 10 "$orrery" run "models/scenes/$scene.yaml" -o "$out/reduce_check.h5" --quiet \
        --set "gear_train.dynamics.flexible_bodies[S.planet1].reduce_input=../bodies/seed003_planet_modes$n.yaml" \
        --set "gear_train.dynamics.flexible_bodies[S.planet1].reduced_body=../bodies/seed003_planet_modes$n.h5" \
        --set solver.end_time=1e-5 --set output.interval=1e-5 >/dev/null
    done
  done
  for scene in seed003_flexible_healthy seed003_flexible_broken_tooth; do
    nice -n 10 "$orrery" run "models/scenes/$scene.yaml" -o "$out/reduce_check.h5" --quiet \
      --set solver.end_time=1e-5 --set output.interval=1e-5 >/dev/null
  done
  rm -f "$out/reduce_check.h5"
  for s in "${studies[@]}"; do
    nice -n 10 "$orrery" study "models/studies/tradeoff/$s.yaml" -o "$out/$s" -j "$jobs"
  done
fi

/usr/bin/python3 tools/plot/tradeoff_plot.py --studies "$out" --images docs/images \
  --doc docs/tradeoff.md

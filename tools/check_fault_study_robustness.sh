#!/usr/bin/env bash
# Whether the headline fault study's figures depend on rounding (docs/performance.md,
# newton-contact section): `orrery fault-study models/scenes/seed003_flexible_broken_tooth.yaml`
# as the README's Quick start runs it, then again with rounding-level perturbations of its
# inputs and with a tighter Newton tolerance, each into its own folder under
# results/fault_study_robustness/. Prints one line per run (healthy SER, faulty SER, dB) and
# fails if a healthy SER leaves the band [reference / BAND, reference * BAND] around the
# unperturbed run's, or a faulty SER moves by more than 1 %.
#
#   bash tools/check_fault_study_robustness.sh          # 4 fault studies, ~4 to 12 min of CPU each
#   BAND=1.5 JOBS=1 bash tools/check_fault_study_robustness.sh
#
# The perturbations are relative 1e-14 changes of the ring's input speed and of the housing's
# polar inertia (a few ulps: what a reordered sum or another compiler moves; the housing's mass
# does not enter the torsional model, so a change of it leaves the files bit-identical), and
# newton_tolerance 1e-11 against the scene's 1e-10 (what the figures converge to).
set -euo pipefail
cd "$(dirname "$0")/.."
band=${BAND:-1.5}
jobs=${JOBS:-2}
orrery=build/bin/orrery
scene=models/scenes/seed003_flexible_broken_tooth.yaml
out=results/fault_study_robustness
[[ -x "$orrery" ]] || bash tools/build.sh
mkdir -p "$out"

names=(reference speed_1e-14 inertia_1e-14 tolerance_1e-11)
sets=("" "--set gear_train.input_speeds.0=80.600000000000806"
      "--set gear_train.dynamics.housing.polar_inertia=1.200000000000012"
      "--set solver.newton_tolerance=1e-11")

# The first run makes the reduced planets (healthy and broken) if they are missing, so that the
# parallel runs never write the same file.
run() {
  # shellcheck disable=SC2086
  nice -n 10 "$orrery" fault-study "$scene" -o "$out/$1" --force --quiet --no-plots $2 > "$out/$1.log" 2>&1
}
run "${names[0]}" "${sets[0]}"
pids=()
for i in "${!names[@]}"; do
  [[ $i -eq 0 ]] && continue
  run "${names[$i]}" "${sets[$i]}" &
  pids+=($!)
  if (( ${#pids[@]} >= jobs )); then wait "${pids[0]}"; pids=("${pids[@]:1}"); fi
done
for p in "${pids[@]}"; do wait "$p"; done

/usr/bin/env python3 - "$out" "$band" "${names[@]}" <<'EOF'
import json, math, sys
out, band, names = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
ref = json.load(open(f"{out}/{names[0]}/summary.json"))["ser"]
ok = True
print(f"{'run':<18} {'healthy SER':>12} {'faulty SER':>11} {'dB':>7}")
for n in names:
    s = json.load(open(f"{out}/{n}/summary.json"))["ser"]
    db = 10 * math.log10(s["faulty"] / s["healthy"])
    h_ok = ref["healthy"] / band <= s["healthy"] <= ref["healthy"] * band
    f_ok = abs(s["faulty"] / ref["faulty"] - 1) <= 0.01
    ok &= h_ok and f_ok
    print(f"{n:<18} {s['healthy']:12.6g} {s['faulty']:11.6g} {db:7.2f}" + ("" if h_ok and f_ok else "  OUT OF BAND"))
print(f"band: healthy SER within x{band} of the reference's, faulty within 1 %: " + ("all in" if ok else "FAILED"))
sys.exit(0 if ok else 1)
EOF

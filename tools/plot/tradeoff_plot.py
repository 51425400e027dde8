#!/usr/bin/env python3
"""The trade study's plots and table (docs/tradeoff.md), from the study indexes.

    tradeoff_plot.py --studies results/studies/tradeoff --images docs/images --doc docs/tradeoff.md

Reads <studies>/<study>/index.csv of the studies below (a missing study is left out with a note),
takes each study's last run as its reference (the studies of models/studies/tradeoff/ list their
most refined setting last) and, for the seed 003 scenarios, the flexible study's reference as the
scenario's reference (the most detailed mesh model). Writes
  <images>/tradeoff_<scenario>.png  error against CPU time per output, the Pareto front marked
  the table between "<!-- tradeoff-table:start -->" and "<!-- tradeoff-table:end -->" of --doc
    (or prints it when --doc is not given).
Needs Debian's python3-matplotlib and python3-numpy (exit 3 naming them when missing); a bad
argument or an unreadable index is one line on stderr, exit 2.
"""
import argparse
import csv
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from orrery_plot import fail, pyplot  # noqa: E402

# Scenarios: (key, title, [(study, label, defaults)]); defaults: the scene's own settings, which
# mark the engine's default run of the study
SCENARIOS = [
    ("seed003_healthy", "Seed 003, healthy", [
        ("seed003_lumped_healthy", "lumped TVMS", {"solver.integrator": "ida", "solver.rtol": "1e-06", "output.interval": "1e-04"}),
        ("seed003_contact_healthy", "rigid contact", {"solver.step": "1e-05", "gear_train.dynamics.tooth_contact.involute_intervals": "40"}),
        ("seed003_flexible_healthy", "flexible planet", {"solver.step": "5e-06", "gear_train.dynamics.flexible_bodies[S.planet1].reduce_input": "../bodies/seed003_planet.yaml"}),
    ]),
    ("seed003_broken_tooth", "Seed 003, planet 1 tooth broken", [
        ("seed003_lumped_broken_tooth", "lumped TVMS", {"solver.integrator": "ida", "solver.rtol": "1e-06", "output.interval": "1e-04"}),
        ("seed003_contact_broken_tooth", "rigid contact", {"solver.step": "1e-05", "gear_train.dynamics.tooth_contact.involute_intervals": "40"}),
        ("seed003_flexible_broken_tooth", "flexible planet", {"solver.step": "5e-06", "gear_train.dynamics.flexible_bodies[S.planet1].reduce_input": "../bodies/seed003_planet.yaml"}),
    ]),
    ("seed002_ramp", "Seed 002, speed ramp", [
        ("seed002_alpha1_ramp", "lumped", {"gear_train.dynamics.dofs": "spatial", "solver.integrator": "generalized_alpha", "solver.step": "1e-04", "solver.rho_inf": "0.5", "output.interval": "0.001"}),
    ]),
]
# How each study's reference converged: pairs of runs (a, b, what changed from a to b); the table
# gives each output's relative change from a to b
CONVERGENCE = {
    "seed003_lumped_healthy": [(5, 6, "IDA rtol 1e-8 to 1e-9 (0.1 ms output)"), (13, 14, "IDA rtol 1e-6 to 1e-9 (0.05 ms output)"), (3, 13, "output 0.1 to 0.05 ms (IDA 1e-6)")],
    "seed003_lumped_broken_tooth": [(5, 6, "IDA rtol 1e-8 to 1e-9 (0.1 ms output)"), (13, 14, "IDA rtol 1e-6 to 1e-9 (0.05 ms output)"), (3, 13, "output 0.1 to 0.05 ms (IDA 1e-6)")],
    "seed003_contact_healthy": [(3, 5, "step 5 to 2.5 us (100 facets)"), (5, 6, "step 2.5 to 1.25 us (100 facets)"), (4, 5, "facets 40 to 100 (2.5 us)")],
    "seed003_contact_broken_tooth": [(1, 2, "step 5 to 2.5 us (40 facets)"), (2, 3, "facets 40 to 100 (2.5 us)")],
    "seed003_flexible_healthy": [(5, 6, "modes 50 to 100 (5 us)"), (3, 4, "step 5 to 2.5 us (24 modes)"), (2, 3, "step 10 to 5 us (24 modes)"),
                                 (6, "seed003_flexible_healthy_refinement:0", "step 5 to 2.5 us (100 modes)"),
                                 (6, "seed003_flexible_healthy_refinement:1", "modes 100 to 200 (5 us)")],
    "seed003_flexible_broken_tooth": [(1, 3, "modes 24 to 50 (5 us)"), (1, 2, "step 5 to 2.5 us (24 modes)")],
    "seed002_alpha1_ramp": [(14, 15, "IDA rtol 1e-8 to 1e-9 (1 ms output)"), (18, 19, "IDA rtol 1e-6 to 1e-9 (0.5 ms output)"), (12, 18, "output 1 to 0.5 ms (IDA 1e-6)")],
}
MEASURED = {"run", "status", "wall_time_s", "cpu_time_s", "peak_memory_mib", "exit_status",
            "reason", "rank", "host", "result_file"}
SHORT = {"gear_train.dynamics.flexible_bodies[S.planet1].reduce_input": "modes",
         "gear_train.dynamics.flexible_bodies[S.planet1].reduced_body": None,
         "gear_train.dynamics.tooth_contact.involute_intervals": "facets",
         "gear_train.dynamics.dofs": "dofs", "solver.integrator": "", "solver.rtol": "rtol",
         "solver.step": "h", "solver.rho_inf": "rho", "output.interval": "out"}
MARKERS = {"lumped TVMS": "o", "rigid contact": "s", "flexible planet": "^", "lumped": "o"}
COLORS = {"lumped TVMS": "C0", "rigid contact": "C1", "flexible planet": "C2", "lumped": "C0"}
START, END = "<!-- tradeoff-table:start -->", "<!-- tradeoff-table:end -->"


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


class Study:
    """One study's index: parameters, outputs, costs per run; the last run is its reference."""

    def __init__(self, folder, name, label, defaults):
        path = os.path.join(folder, name, "index.csv")
        try:
            with open(path, newline="") as f:
                rows = list(csv.reader(f))
        except OSError as e:
            raise ValueError(f"{path}: {e.strerror}")
        if len(rows) < 2 or "cpu_time_s" not in rows[0]:
            raise ValueError(f"{path}: not a study index (no runs or no cpu_time_s column)")
        head = rows[0]
        first_measured = head.index("wall_time_s")
        self.name, self.label = name, label
        self.columns = head[2:first_measured]
        self.rows = [dict(zip(head, r)) for r in rows[1:]]
        self.ok = [r["status"] == "ok" for r in self.rows]
        self.reference = self.rows[-1]
        self.default = next((i for i, r in enumerate(self.rows)
                             if all(r.get(k) == v for k, v in defaults.items())), None)

    def settings(self, i):
        parts = []
        for key, value in self.rows[i].items():
            if key in MEASURED or key not in self.parameter_keys:
                continue
            short = SHORT.get(key, key)
            integrator = self.rows[i].get("solver.integrator", "")
            # IDA has no fixed step, generalized-alpha no tolerance: leave them out
            if short is None or (short == "h" and integrator == "ida") or \
                    (short in ("rtol",) and integrator == "generalized_alpha"):
                continue
            if short == "modes":
                base = os.path.basename(value)
                value = base.replace("seed003_planet_modes", "").replace(".yaml", "")
                value = "24" if base == "seed003_planet.yaml" else value
            if short == "":
                value = {"generalized_alpha": "g-alpha", "ida": "IDA"}.get(value, value)
                parts.append(value)
            else:
                parts.append(f"{short} {value}")
        return ", ".join(parts)


def load(folder, name, label, defaults, outputs):
    s = Study(folder, name, label, defaults)
    s.outputs_cache = set(outputs)
    s.parameter_keys = [c for c in s.columns if c not in outputs]
    return s


def rel_error(x, ref):
    if math.isnan(x) or math.isnan(ref) or ref == 0:
        return math.nan
    return abs(x - ref) / abs(ref)


def pareto(points):
    """Indices of (cost, error) points no other point beats in both (one strictly)."""
    front = []
    for i, (c, e) in enumerate(points):
        if not any((c2 <= c and e2 <= e and (c2 < c or e2 < e)) for j, (c2, e2) in enumerate(points) if j != i):
            front.append(i)
    return front


def fmt_err(e):
    if math.isnan(e):
        return "—"
    if e == 0:
        return "0"
    p = 100 * e
    return f"{p:.2g} %" if p < 10 else f"{p:.0f} %"


def fmt_value(x):
    return "—" if math.isnan(x) else f"{x:.4g}"


def defaults_table(s, outputs):
    """Where the study's default run sits, output by output, against its own reference: its
    error, and whether another run beats it clearly (as accurate at 80 % of its CPU time, or half
    as wrong within 120 % of it), naming the most accurate such run."""
    if s.default is None:
        return [f"| {s.label} | no default run in the study | |"]
    cells = []
    for o in outputs:
        if o not in s.reference:
            continue
        ref = number(s.reference[o])
        pts = []
        for i, r in enumerate(s.rows):
            if r["status"] in ("ok", "output_failed"):
                e, c = rel_error(number(r[o]), ref), number(r["cpu_time_s"])
                if not (math.isnan(e) or math.isnan(c)):
                    pts.append((i, c, e))
        d = [p for p in pts if p[0] == s.default]
        if not d:
            cells.append(f"{o}: —")
            continue
        _, cd, ed = d[0]
        # Beaten clearly: as accurate at 80 % of the CPU time, or half the error within 120 % of
        # it (CPU times of a shared machine scatter by some 10-20 % between passes)
        better = [p for p in pts if p[0] != s.default and
                  ((p[1] <= 0.8 * cd and p[2] <= ed) or (p[1] <= 1.2 * cd and p[2] <= 0.5 * ed))]
        if not better:
            cells.append(f"{o}: {fmt_err(ed)}, on the front")
        else:
            b = min(better, key=lambda p: (p[2], p[1]))
            cells.append(f"{o}: {fmt_err(ed)}, off (run {b[0]}: {fmt_err(b[2])} at {b[1]:.3g} s)")
    return [f"| {s.label} | {s.default}: {s.settings(s.default)} | {number(s.rows[s.default]['cpu_time_s']):.3g} | "
            + "; ".join(cells) + " |"]


def convergence_table(s, outputs, folder):
    """Each convergence pair of the study: every output's relative change from run a to run b."""
    lines = []
    for a, b, what in CONVERGENCE.get(s.name, []):
        ra, rb = row_of(s, a, folder), row_of(s, b, folder)
        if ra is None or rb is None:
            lines.append(f"| {s.name} | {what} (runs {a}, {b}) | not run |")
            continue
        cells = [f"{o} {fmt_err(rel_error(number(ra[o]), number(rb[o])))}" for o in outputs if o in ra and o in rb]
        lines.append(f"| {s.name} | {what} (runs {a} to {b}) | " + "; ".join(cells) + " |")
    return lines


def row_of(s, ref, folder):
    """Run `ref` of study s (an int), or "STUDY:RUN" of another study's index.csv in folder; None
    when it has not run."""
    rows = s.rows
    if isinstance(ref, str):
        name, run = ref.split(":")
        try:
            with open(os.path.join(folder, name, "index.csv"), newline="") as f:
                rows = list(csv.DictReader(f))
        except OSError:
            return None
        ref = int(run)
    if ref >= len(rows) or rows[ref]["status"] not in ("ok", "output_failed"):
        return None
    return rows[ref]


def study_table(s, outputs, scenario_ref):
    """Markdown rows of one study: settings, costs, each output's error against the study's
    reference (and, for seed 003, against the scenario's reference in brackets)."""
    lines = []
    ref = s.reference
    for i, r in enumerate(s.rows):
        tag = " (reference)" if i == len(s.rows) - 1 else ""
        tag += " **default**" if i == s.default else ""
        if r["status"] not in ("ok", "output_failed"):
            lines.append(f"| {s.label} | {i}: {s.settings(i)}{tag} | {r['status']}: {r['reason'][:60]} |" + " |" * (2 + len(outputs)))
            continue
        cells = []
        for o in outputs:
            if o not in r:
                cells.append("")
                continue
            x = number(r[o])
            own = rel_error(x, number(ref[o]))
            cell = fmt_value(x) if i == len(s.rows) - 1 else fmt_err(own)
            if scenario_ref is not None and scenario_ref is not ref and o in scenario_ref:
                cell += f" [{fmt_err(rel_error(x, number(scenario_ref[o])))}]"
            cells.append(cell)
        lines.append(f"| {s.label} | {i}: {s.settings(i)}{tag} | {number(r['cpu_time_s']):.3g} | "
                     f"{number(r['wall_time_s']):.3g} | {number(r['peak_memory_mib']):.0f} | " + " | ".join(cells) + " |")
    return lines


def plot_scenario(plt, key, title, studies, outputs, scenario_ref, images):
    n = len(outputs)
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.6 * rows), squeeze=False)
    for k, o in enumerate(outputs):
        ax = axes[k // cols][k % cols]
        points, labels = [], []
        for s in studies:
            xs, ys = [], []
            for i, r in enumerate(s.rows):
                if r["status"] not in ("ok", "output_failed") or o not in r:
                    continue
                e = rel_error(number(r[o]), number(scenario_ref[o]))
                c = number(r["cpu_time_s"])
                if math.isnan(e) or math.isnan(c):
                    continue
                e = max(e, 1e-7)  # the reference itself (0) at the plot's floor
                xs.append(c), ys.append(e)
                points.append((c, e)), labels.append((s, i))
                if i == s.default:
                    ax.plot([c], [e], "o", ms=12, mfc="none", mec="red", zorder=4)
            ax.plot(xs, ys, MARKERS.get(s.label, "o"), color=COLORS.get(s.label, "C0"), label=s.label, alpha=0.8)
        ax.set_title(o, fontsize=10)
        if not points:
            ax.text(0.5, 0.5, "no finished run", ha="center", va="center", transform=ax.transAxes)
            continue
        front = sorted(pareto(points), key=lambda i: points[i][0])
        ax.step([points[i][0] for i in front], [points[i][1] for i in front], "k-", where="post", lw=1,
                label="Pareto front")
        ax.set_xscale("log"), ax.set_yscale("log")
        ax.set_xlabel("CPU time of the run (s)"), ax.set_ylabel("relative error")
        ax.grid(True, which="both", alpha=0.3)
        if k == 0:
            ax.legend(fontsize=7)
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle(f"{title}: error against the reference, red ring = the scene's own setting "
                 f"(errors below 1e-7 drawn at 1e-7)", fontsize=10)
    fig.tight_layout()
    path = os.path.join(images, f"tradeoff_{key}.png")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--studies", required=True, help="folder holding the study folders")
    p.add_argument("--images", required=True, help="folder for tradeoff_*.png")
    p.add_argument("--doc", help="Markdown file whose table markers receive the table")
    a = p.parse_args()
    if not os.path.isdir(a.studies):
        fail(f"--studies {a.studies}: no such folder")
    if a.doc and not os.path.isfile(a.doc):
        fail(f"--doc {a.doc}: no such file")
    plt = pyplot()
    os.makedirs(a.images, exist_ok=True)
    table, notes, all_studies = [], [], []
    for key, title, members in SCENARIOS:
        studies = []
        for name, label, defaults in members:
            if not os.path.isfile(os.path.join(a.studies, name, "index.csv")):
                notes.append(f"{name}: not run")
                continue
            try:
                with open(os.path.join(a.studies, name, "index.csv"), newline="") as f:
                    head = next(csv.reader(f))
                outputs = head[head.index("status") + 1:head.index("wall_time_s")]
                # Parameters are scene keys (with dots); outputs are names from the study file
                outputs = [c for c in outputs if c not in SHORT and not c.startswith(("gear_train.", "solver.", "output."))]
                studies.append(load(a.studies, name, label, defaults, outputs))
            except (ValueError, StopIteration) as e:
                fail(f"{name}: {e}")
        if not studies:
            continue
        all_studies += studies
        outputs = []
        for s in studies:
            outputs += [o for o in s.outputs_cache if o not in outputs]
        order = [o for o in studies[-1].columns if o in outputs] + [o for o in outputs if o not in studies[-1].columns]
        scenario_ref = studies[-1].reference
        plot_scenario(plt, key, title, studies, order, scenario_ref, a.images)
        table.append(f"\n**{title}** (`tradeoff_{key}.png`). Errors against the study's own reference "
                     "(its last run, values shown)" + (", in brackets against the flexible study's reference"
                                                       if len(studies) > 1 else "") + ".\n")
        table.append("| model | run: settings | CPU s | wall s | MiB | " + " | ".join(order) + " |")
        table.append("|---|---|---|---|---|" + "---|" * len(order))
        for s in studies:
            table += study_table(s, order, scenario_ref if len(studies) > 1 else None)
    table.append("\n**How the references converged** (relative change of each output between two runs "
                 "that differ in one setting, the second the reference or nearer to it).\n")
    table.append("| study | refinement | change per output |")
    table.append("|---|---|---|")
    for s in all_studies:
        table += convergence_table(s, [o for o in s.columns if o in s.outputs_cache], a.studies)
    table.append("\n**Where the defaults sit** (each study's default run, each output's error against "
                 "the study's reference; off the front: a run beats it clearly, as accurate at 80 % of its "
                 "CPU time or half as wrong within 120 % of it; the most accurate such run is named).\n")
    table.append("| model | default run | CPU s | outputs |")
    table.append("|---|---|---|---|")
    for s in all_studies:
        table += defaults_table(s, [o for o in s.columns if o in s.outputs_cache])
    if notes:
        table.append("\n" + "; ".join(notes) + ".")
    text = "\n".join(table) + "\n"
    if not a.doc:
        print(text)
        return
    with open(a.doc) as f:
        doc = f.read()
    if START not in doc or END not in doc:
        fail(f"--doc {a.doc}: no {START} ... {END} markers")
    doc = doc[:doc.index(START) + len(START)] + "\n" + text + doc[doc.index(END):]
    with open(a.doc, "w") as f:
        f.write(doc)


if __name__ == "__main__":
    main()

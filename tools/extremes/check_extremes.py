#!/usr/bin/env python3
"""Accuracy checks of the stability-at-the-extremes studies (models/studies/extremes_*.yaml).

Reads each study's index.csv and run logs under RESULTS (default results/studies) and prints
the outcome table of docs/extremes.md: per run, the check against its oracle (closed forms
named in each study file; the step family against generalized-alpha's own recurrence, with the
continuous closed form's error beside it), and one of
  meets        the run ended and its check holds;
  warns        the run ended, its check fails, and the run warned (its health line names why);
  stops        the run stopped with a message naming the time and the element;
  FAILS        anything else: a check that fails silently, a NaN, a crash, a stop without
               time or element.
Exit status 1 when any run FAILS. Standard library only.
"""
import csv
import math
import os
import re
import sys

X0 = 1e-3            # oscillator: initial displacement (m), models/scenes/oscillator.yaml
WILLIS = (50 * 80.6 + 22 * -10) / 72   # seed 003 carrier speed (rad/s) with Z_r 50, Z_s 22
R, L = 0.1, 0.3      # slider crank (m)


def num(row, key):
    try:
        return float(row[key])
    except (KeyError, ValueError):
        return math.nan


def oscillator(row):
    """max(|x - x_exact| / x0, |v - v_exact| / (w x0)) at the last row: the damped closed form."""
    k = num(row, "force_elements.spring.stiffness")
    k = 1e6 if math.isnan(k) else k
    c = num(row, "force_elements.spring.damping")
    c = 0.0 if math.isnan(c) else c
    w = math.sqrt(k / 1.0)
    z = c / (2 * math.sqrt(k * 1.0))
    t = num(row, "t_final")
    if z < 1:
        wd = w * math.sqrt(1 - z * z)
        e = math.exp(-z * w * t)
        x = X0 * e * (math.cos(wd * t) + z / math.sqrt(1 - z * z) * math.sin(wd * t))
        v = -X0 * e * w * w / wd * math.sin(wd * t)
    else:
        x = X0 * (1 + w * t) * math.exp(-w * t)
        v = -X0 * w * w * t * math.exp(-w * t)
    err = max(abs(num(row, "x_final") - x) / X0, abs(num(row, "v_final") - v) / (w * X0))
    return err, 1e-2, "end state vs closed form, /x0"


NEWTON_TOLERANCE = 1e-8   # generalized-alpha's default (mbd/integrator.h), the step study's


def alpha_parameters(rho):
    """Chung & Hulbert (1993, J. Appl. Mech. 60:371, eqs. 25 and 17) from the spectral radius at
    infinity: alpha_m, alpha_f, gamma, beta."""
    am = (2 * rho - 1) / (rho + 1)
    af = rho / (rho + 1)
    gamma = 0.5 + af - am
    return am, af, gamma, 0.25 * (gamma + 0.5) ** 2


def output_steps(end_time, interval, step):
    """The steps generalized-alpha takes to end_time (mbd/output_schedule.cpp, mbd/generalized_alpha.cpp
    AdvanceTo): output k at k * interval, the last at the end time; between two outputs
    n = ceil(span / step - 1e-6) equal steps."""
    rows = math.ceil(end_time / interval - 1e-9) + 1
    steps, t = [], 0.0
    for k in range(1, rows):
        t_out = end_time if k == rows - 1 else min(k * interval, end_time)
        span = t_out - t
        n = max(1, math.ceil(span / step - 1e-6))
        steps += [span / n] * n
        t = t_out
    return steps


def alpha_oscillator(k, c, rho, steps, x0=X0, m=1.0):
    """The generalized-alpha recurrence (Chung & Hulbert 1993, in the pseudo-acceleration form of
    Arnold & Bruls 2007, which the engine implements and which has the same amplification matrix on
    linear problems) for m x'' + c x' + k x = 0 from (x0, 0), a_0 = x''_0, applied step by step:
        (1 - alpha_m) a_1 + alpha_m a_0 = (1 - alpha_f) xdd_1 + alpha_f xdd_0,
        v_1 = v_0 + h (1 - gamma) a_0 + h gamma a_1,
        x_1 = x_0 + h v_0 + h^2 (1/2 - beta) a_0 + h^2 beta a_1,   m xdd_1 + c v_1 + k x_1 = 0,
    linear in xdd_1, solved exactly. Returns (x, v) at the end."""
    am, af, gamma, beta = alpha_parameters(rho)
    x, v = x0, 0.0
    xdd = -(k * x + c * v) / m
    a = xdd
    for h in steps:
        # a_1 = p + r xdd_1, then v_1 and x_1 affine in xdd_1
        r = (1 - af) / (1 - am)
        p = (af * xdd - am * a) / (1 - am)
        v_p = v + h * (1 - gamma) * a + h * gamma * p
        x_p = x + h * v + h * h * (0.5 - beta) * a + h * h * beta * p
        xdd_new = -(c * v_p + k * x_p) / (m + c * h * gamma * r + k * h * h * beta * r)
        a_new = p + r * xdd_new
        v = v_p + h * gamma * r * xdd_new
        x = x_p + h * h * beta * r * xdd_new
        xdd, a = xdd_new, a_new
    return x, v


def step_family(row):
    """The end state against the scheme's own recurrence (alpha_oscillator), within N Newton
    tolerances of x0 (each step solved to the tolerance, its error carried by a recurrence of
    spectral radius <= 1); the continuous closed form's error (the step's physical error) beside."""
    k = 1e6
    w = math.sqrt(k)
    steps = output_steps(num(row, "t_final"), num(row, "output.interval"), num(row, "solver.step"))
    x, v = alpha_oscillator(k, 0.0, num(row, "solver.rho_inf"), steps)
    err = max(abs(num(row, "x_final") - x) / X0, abs(num(row, "v_final") - v) / (w * X0))
    physical, _, _ = oscillator(row)
    tol = len(steps) * NEWTON_TOLERANCE
    return err, tol, "end state vs the generalized-alpha recurrence (%d steps), /x0" % len(steps), physical


def carrier(row):
    speeds = row.get("gear_train.input_speeds", "")
    willis = WILLIS
    if speeds:
        wr, ws = [float(s) for s in speeds.strip("[]").split(",")]
        willis = (50 * wr + 22 * ws) / 72
    err = abs(num(row, "carrier_speed_mean") - willis) / abs(willis)
    return err, 1e-2, "carrier mean speed vs Willis, relative"


def slider(row):
    rpm = float(re.search(r"value_rpm: *([0-9.e+-]+)", row["drivers.motor.function"]).group(1))
    w = rpm * math.pi / 30
    es = abs(num(row, "s_final") - math.sqrt(L * L - R * R)) / 1e-6
    ev = abs(num(row, "v_final") + R * w) / (1e-4 * R * w)
    return max(es, ev), 1.0, "end slider position /1e-6 m, speed /1e-4 r w"


def four_bar(row):
    err = abs(num(row, "rocker_final") - num(row, "crank_final"))
    return err, 1e-6, "|rocker - crank| at the end (rad)"


def long_run(row):
    # Energy: peak residual against the swing's energy; no secular trend: the second half's peak
    # within 2x the first's (rho_inf 1); drift: |Phi| at the Newton tolerance's level.
    rel = num(row, "energy_residual_peak") / num(row, "kinetic_peak")
    return rel, 1e-3, "peak energy residual / peak kinetic energy"


def backlash(row):
    reversed_ = num(row, "flank_min") == -1 and num(row, "flank_max") == 1
    err, tol, _ = carrier(row)
    return (err if reversed_ else math.inf), tol, "carrier speed vs Willis (inf: no flank change)"


CHECKS = {
    "extremes_stiffness": oscillator, "extremes_damping": oscillator, "extremes_step": step_family,
    "extremes_mesh_stiffness": carrier, "extremes_contact_stiffness": carrier,
    "extremes_planet_mass": carrier, "extremes_train_speed": carrier, "extremes_speed": slider,
    "extremes_large_step": carrier, "extremes_four_bar": four_bar, "extremes_long": long_run, "extremes_backlash": backlash,
}
# A clean stop names the time and an element.
CLEAN = re.compile(r"t = [-+0-9.e]+ s.*(joint|mesh|loop closure|driver|body|contact|element|constraint|row)")


def log_of(folder, row):
    path = os.path.join(folder, "runs", "run_%05d.log" % int(row["run"]))
    try:
        with open(path, errors="replace") as f:
            return f.read()
    except OSError:
        return ""


def outcome(folder, study, row, params):
    text = log_of(folder, row)
    health = re.search(r"^health +(.*)$", text, re.M)
    health = health.group(1) if health else ""
    if row["status"] != "ok":
        reason = row["reason"]
        if CLEAN.search(reason):
            return "stops", reason
        return "FAILS", "unclean stop: " + reason
    err, tol, what, *extra = CHECKS[study](row)
    detail = "%s = %.3g (tolerance %.3g); health: %s" % (what, err, tol, health)
    if extra:
        # The step family: the physical error of the step, against the continuous closed form
        detail += "; vs the closed form x0 cos(w t): %.3g x0" % extra[0]
    if err <= tol and not (study == "extremes_backlash" and "warning" in health):
        return "meets", detail
    if "warning" in health:
        return "warns", detail
    return "FAILS", detail


def main():
    results = sys.argv[1] if len(sys.argv) > 1 else "results/studies"
    failed = 0
    print("| study | run | parameters | outcome | check / message |")
    print("|---|---|---|---|---|")
    for study in CHECKS:
        folder = os.path.join(results, study)
        index = os.path.join(folder, "index.csv")
        if not os.path.exists(index):
            continue
        with open(index, newline="") as f:
            rows = list(csv.DictReader(f))
        skip = {"run", "status", "wall_time_s", "cpu_time_s", "peak_memory_mib", "exit_status",
                "reason", "rank", "host", "result_file"}
        with open(os.path.join(folder, "study.yaml")) as f:
            text = f.read()
        keys = [k for k in rows[0] if k not in skip and re.search(r"key: *\"?" + re.escape(k), text)]
        for row in rows:
            params = ", ".join("%s=%s" % (k.split(".")[-1], row[k]) for k in keys
                               if k not in ("solver.end_time", "output.interval") or study == "extremes_four_bar")
            kind, detail = outcome(folder, study, row, params)
            failed += kind == "FAILS"
            print("| %s | %s | %s | %s | %s (%.2f s) |" % (study[9:], row["run"], params.replace("|", "/"), kind,
                                                           detail.replace("|", "/"), num(row, "wall_time_s")))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())

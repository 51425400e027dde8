#!/usr/bin/env python3
"""Amplitude spectrum with its peaks labelled and the kinematic lines marked.

Usage: spectrum_plot.py --data SPECTRUM.json --out SPECTRUM.png
Data (written by `orrery spectrum --png`): title, x_label, y_label, x, amplitude,
peaks [{x, amplitude, label}], lines [{name, x, kind}] (lines in the units of x).
Top: the spectrum up to a little beyond its highest listed peak (at least four mesh harmonics),
mesh harmonics marked. Bottom: a zoom on the first mesh line (or the largest peak) with the
sideband positions of the other lines marked and the peaks labelled.
"""
import argparse

import orrery_plot

COLOURS = {"mesh": "tab:red", "shaft": "tab:green", "planet_pass": "tab:purple", "fault": "tab:orange"}


def draw_spectrum(ax, x, y, lo, hi, floor):
    keep = [i for i, v in enumerate(x) if lo <= v <= hi]
    ys = [max(y[i], floor) for i in keep]
    ax.semilogy([x[i] for i in keep], ys, lw=0.7, color="tab:blue")
    top = max(ys, default=1.0)
    ax.set_ylim(max(floor, top * 1e-6), top * 8)
    ax.set_xlim(lo, hi)
    ax.grid(True, which="both", lw=0.3, alpha=0.4)


def mark(ax, f, text, colour, style="--"):
    ax.axvline(f, color=colour, ls=style, lw=0.8)
    if text:
        ax.annotate(text, (f, 1.0), xycoords=("data", "axes fraction"), rotation=90, va="top", ha="right",
                    fontsize=7, color=colour)


def label_peaks(ax, peaks, lo, hi):
    shown = [p for p in peaks if lo <= p["x"] <= hi]
    for rank, p in enumerate(sorted(shown, key=lambda p: p["x"])):
        ax.plot(p["x"], p["amplitude"], "v", color="black", ms=4)
        if p.get("label"):
            ax.annotate(p["label"], (p["x"], p["amplitude"]), textcoords="offset points",
                        xytext=(3, 6 + 9 * (rank % 3)), fontsize=7)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    d = orrery_plot.load_json(args.data)
    plt = orrery_plot.pyplot()

    x, y = d["x"], orrery_plot.finite(d["amplitude"])
    floor = orrery_plot.positive_floor(y)
    peaks, lines = d.get("peaks", []), [line for line in d.get("lines", []) if line["x"] > 0]
    mesh = [line for line in lines if line["kind"] == "mesh"]
    side = [line for line in lines if line["kind"] != "mesh"]

    # Top: up to 1.15 x the highest listed peak, at least 4 mesh harmonics
    hi = max([p["x"] for p in peaks] + [0.0]) * 1.15
    if mesh:
        hi = max(hi, 4.3 * mesh[0]["x"])
    hi = min(x[-1], hi) if hi > 0 else x[-1]
    fig, (whole, zoom) = plt.subplots(2, 1, figsize=(11, 8.5))
    draw_spectrum(whole, x, y, x[0], hi, floor)
    for m in mesh:
        k = 1
        while k * m["x"] <= hi:
            mark(whole, k * m["x"], (f"{k} " if k > 1 else "") + m["name"], COLOURS["mesh"])
            k += 1
    label_peaks(whole, peaks[:8], x[0], hi)
    whole.set_title(d.get("title", "Amplitude spectrum"))
    whole.set_xlabel(d.get("x_label", "frequency (Hz)"))
    whole.set_ylabel(d.get("y_label", "amplitude"))

    # Bottom: the first mesh line with the sideband positions of the other lines
    if mesh:
        centre = mesh[0]["x"]
        spacing = min([s["x"] for s in side if s["x"] < centre / 2], default=centre / 10)
        lo, up = centre - 6.5 * spacing, centre + 6.5 * spacing
        title = f"around {mesh[0]['name']}: sideband positions of " + ", ".join(
            sorted({s["name"] for s in side if s["x"] < centre / 2})) if side else f"around {mesh[0]['name']}"
    else:
        centre = peaks[0]["x"] if peaks else x[len(x) // 2]
        lo, up = centre * 0.8, centre * 1.2
        title = "around the largest peak"
    lo, up = max(x[0], lo), min(x[-1], up)
    draw_spectrum(zoom, x, y, lo, up, floor)
    if mesh:
        mark(zoom, centre, mesh[0]["name"], COLOURS["mesh"])
        for s in side:
            n = 1
            while s["x"] < centre / 2 and n * s["x"] <= up - centre:
                for f in (centre - n * s["x"], centre + n * s["x"]):
                    mark(zoom, f, "", COLOURS.get(s["kind"], "gray"), ":")
                n += 1
    label_peaks(zoom, peaks, lo, up)
    zoom.set_title(title, fontsize=9)
    zoom.set_xlabel(d.get("x_label", "frequency (Hz)"))
    zoom.set_ylabel(d.get("y_label", "amplitude"))
    handles = [plt.Line2D([], [], color=c, ls="--" if k == "mesh" else ":", label=k + " line")
               for k, c in COLOURS.items() if any(line["kind"] == k for line in lines)]
    if handles:
        zoom.legend(handles=handles, loc="upper right", fontsize=8)
    fig.tight_layout()
    orrery_plot.save(fig, args.out)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Healthy and faulty amplitude spectra overlaid, with the mesh harmonics and their sidebands.

Usage: overlay_plot.py --data COMPARE.json --out OVERLAY.png
Data (written by `orrery compare --png`): title, x_label, y_label, x, healthy, faulty,
mesh {name, x}, modulation {name, x}, sidebands (pairs per harmonic), harmonics,
ser {healthy, faulty, ratio}.
Top: the whole spectrum; bottom: the first mesh harmonic and its sidebands.
"""
import argparse

import orrery_plot


def draw(ax, d, lo, hi, floor):
    x = d["x"]
    keep = [i for i, v in enumerate(x) if lo <= v <= hi]
    xs = [x[i] for i in keep]
    for key, colour, width in (("healthy", "tab:blue", 0.9), ("faulty", "tab:red", 0.7)):
        ys = orrery_plot.finite(d[key])
        ax.semilogy(xs, [max(ys[i], floor) for i in keep], color=colour, lw=width, label=key, alpha=0.85)
    f_m, f_x = d["mesh"]["x"], d["modulation"]["x"]
    for k in range(1, d.get("harmonics", 3) + 1):
        if lo <= k * f_m <= hi:
            ax.axvline(k * f_m, color="black", ls="--", lw=0.8)
            ax.annotate((f"{k} " if k > 1 else "") + d['mesh']['name'], (k * f_m, 1.0), xycoords=("data", "axes fraction"),
                        rotation=90, va="top", ha="right", fontsize=7)
        for n in range(1, d.get("sidebands", 0) + 1):
            for s in (-1, 1):
                f = k * f_m + s * n * f_x
                if lo <= f <= hi:
                    ax.axvline(f, color="tab:orange", ls=":", lw=0.8)
    ax.set_xlim(lo, hi)
    ax.set_xlabel(d.get("x_label", "frequency (Hz)"))
    ax.set_ylabel(d.get("y_label", "amplitude"))
    ax.grid(True, which="both", lw=0.3, alpha=0.5)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    d = orrery_plot.load_json(args.data)
    plt = orrery_plot.pyplot()

    floor = orrery_plot.positive_floor(orrery_plot.finite(d["healthy"]) + orrery_plot.finite(d["faulty"]))
    f_m, f_x = d["mesh"]["x"], d["modulation"]["x"]
    fig, (whole, zoom) = plt.subplots(2, 1, figsize=(11, 8))
    draw(whole, d, d["x"][0], min(d["x"][-1], (d.get("harmonics", 3) + 1) * f_m), floor)
    span = (d.get("sidebands", 3) + 1.5) * f_x
    draw(zoom, d, max(d["x"][0], f_m - span), min(d["x"][-1], f_m + span), floor)
    ser = d.get("ser", {})

    def fmt(v):
        return "n/a" if v is None else f"{v:.4g}"
    whole.set_title(d.get("title", "Healthy and faulty spectra"))
    zoom.set_title(f"{d['mesh']['name']} and sidebands at {d['modulation']['name']} ({f_x:.4g}): "
                   f"SER healthy {fmt(ser.get('healthy'))}, faulty {fmt(ser.get('faulty'))}, "
                   f"faulty/healthy {fmt(ser.get('ratio'))}", fontsize=9)
    handles, _ = whole.get_legend_handles_labels()
    handles += [plt.Line2D([], [], color="black", ls="--", lw=0.8, label="mesh harmonic"),
                plt.Line2D([], [], color="tab:orange", ls=":", lw=0.8,
                           label=f"sideband k {d['mesh']['name']} ± n {d['modulation']['name']}")]
    whole.legend(handles=handles, loc="upper right", fontsize=8)
    fig.tight_layout()
    orrery_plot.save(fig, args.out)


if __name__ == "__main__":
    main()

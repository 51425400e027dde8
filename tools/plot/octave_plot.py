#!/usr/bin/env python3
"""One-third-octave band levels as bars.

Usage: octave_plot.py --data OCTAVE.json --out OCTAVE.png
Data (written by `orrery octave --png`): title, x_label, y_label, bands [{nominal_hz, level_db}].
"""
import argparse

import orrery_plot


def nominal(f):
    return f"{f / 1000:g}k" if f >= 1000 else f"{f:g}"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    d = orrery_plot.load_json(args.data)
    plt = orrery_plot.pyplot()

    bands = d["bands"]
    levels = orrery_plot.finite([b["level_db"] for b in bands])
    fig, ax = plt.subplots(figsize=(max(8, 0.32 * len(bands) + 2), 5))
    finite = [v for v in levels if v == v]
    base = min(finite) - 10 if finite else 0
    ax.bar(range(len(bands)), [v - base if v == v else 0 for v in levels], bottom=base, color="tab:blue",
           edgecolor="black", lw=0.4)
    ax.set_xticks(range(len(bands)))
    ax.set_xticklabels([nominal(b["nominal_hz"]) for b in bands], rotation=90, fontsize=8)
    ax.set_title(d.get("title", "One-third-octave band levels"))
    ax.set_xlabel(d.get("x_label", "one-third-octave band, nominal mid-band frequency (Hz)"))
    ax.set_ylabel(d.get("y_label", "level (dB)"))
    ax.grid(True, axis="y", lw=0.3, alpha=0.5)
    fig.tight_layout()
    orrery_plot.save(fig, args.out)


if __name__ == "__main__":
    main()

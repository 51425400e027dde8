#!/usr/bin/env python3
"""A recorded signal over time.

Usage: time_signal_plot.py --data SIGNAL.json --out SIGNAL.png
Data (written by `orrery plot --signal`): title, x_label, y_label, time, values.
"""
import argparse

import orrery_plot


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    d = orrery_plot.load_json(args.data)
    plt = orrery_plot.pyplot()

    fig, ax = plt.subplots(figsize=(11, 4.5))
    ax.plot(d["time"], orrery_plot.finite(d["values"]), lw=0.6, color="tab:blue")
    ax.set_title(d.get("title", "Signal"))
    ax.set_xlabel(d.get("x_label", "time (s)"))
    ax.set_ylabel(d.get("y_label", "value"))
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    orrery_plot.save(fig, args.out)


if __name__ == "__main__":
    main()

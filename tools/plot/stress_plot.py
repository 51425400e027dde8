#!/usr/bin/env python3
"""Hot-spot (largest von Mises) stress of a flexible body over time, read from a result file.

Usage: stress_plot.py --h5 RUN.h5 --dataset /flexible_bodies/NAME/von_mises_max --out STRESS.png
The dataset has one row per output time (/time): the stress in Pa, then optionally the node id
and its x, y, z in the body frame (m) (mbd/result_recorder.h). The largest value is marked with
its node and place.
"""
import argparse

import orrery_plot


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--h5", required=True)
    parser.add_argument("--dataset", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--title", default="")
    args = parser.parse_args()
    h5py = orrery_plot.h5py_module()
    plt = orrery_plot.pyplot()

    try:
        f = h5py.File(args.h5, "r")
    except OSError as e:
        orrery_plot.fail(f"{args.h5}: {e}")
    with f:
        if args.dataset not in f or not isinstance(f[args.dataset], h5py.Dataset):
            orrery_plot.fail(f"{args.h5}: {args.dataset}: no such dataset")
        if "/time" not in f:
            orrery_plot.fail(f"{args.h5}: /time: no such dataset")
        data = f[args.dataset][()]
        time = f["/time"][()].reshape(-1)
    if data.ndim == 1:
        data = data.reshape(-1, 1)
    if data.shape[0] != time.shape[0]:
        orrery_plot.fail(f"{args.h5}: {args.dataset}: {data.shape[0]} rows, /time has {time.shape[0]}")
    if data.shape[0] == 0:
        orrery_plot.fail(f"{args.h5}: {args.dataset}: no rows")

    stress_mpa = data[:, 0] / 1e6
    fig, ax = plt.subplots(figsize=(11, 4.5))
    ax.plot(time, stress_mpa, lw=0.7, color="tab:red")
    i = int(stress_mpa.argmax())
    note = f"max {stress_mpa[i]:.4g} MPa at t = {time[i]:.4g} s"
    if data.shape[1] >= 5:
        node = int(data[i, 1])
        x, y, z = (1000 * data[i, 2], 1000 * data[i, 3], 1000 * data[i, 4])
        note += f", node {node} at ({x:.2f}, {y:.2f}, {z:.2f}) mm"
    ax.plot(time[i], stress_mpa[i], "o", color="black", ms=4)
    ax.text(0.99, 0.02, note, transform=ax.transAxes, ha="right", va="bottom", fontsize=8,
            bbox={"facecolor": "white", "edgecolor": "gray", "alpha": 0.9})
    name = args.dataset.strip("/").split("/")
    body = name[1] if len(name) > 2 and name[0] == "flexible_bodies" else args.dataset
    ax.set_title(args.title or f"Hot-spot von Mises stress of {body}")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("largest von Mises stress (MPa)")
    ax.grid(True, lw=0.3, alpha=0.5)
    fig.tight_layout()
    orrery_plot.save(fig, args.out)


if __name__ == "__main__":
    main()

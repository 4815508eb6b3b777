#!/usr/bin/python3
"""Plots the per-step force series of a Surge run (docs/results-format.md, "Force series").

Usage:
  /usr/bin/python3 scripts/plot_forces.py RESULT.h5 [--obstacle NAME] [--faces] [--out PNG]

One panel per structure (and per face with --faces): F_x, F_y, F_z and |F| against time, with
the peak of |F| marked (the first row that reaches it, as the writer's peak_force attribute).
Default output: RESULT_forces.png beside the .h5. Needs Debian's python3-h5py and matplotlib.
"""
import argparse
import os
import sys

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def text(value):
    return value.decode("utf-8") if isinstance(value, bytes) else str(value)


def names(attrs, key, fallback):
    listed = text(attrs[key]) if key in attrs else ""
    return listed.split(",") if listed else list(fallback)


def panels(forces, structures, faces):
    """(label, time, force n x 3, units) for every structure and, with faces, every face."""
    for name in structures:
        group = forces[name]
        time = group["time"][:]
        yield name, time, group["force"][:], text(group["force"].attrs.get("units", "N"))
        if faces:
            for face in names(group.attrs, "faces", group["faces"].keys()):
                data = group["faces"][face]["force"]
                yield f"{name}/{face}", time, data[:], text(data.attrs.get("units", "N"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("result", help="the run's .h5 file")
    parser.add_argument("--obstacle", help="plot only this structure (e.g. domain)")
    parser.add_argument("--faces", action="store_true", help="also plot every face")
    parser.add_argument("--out", help="PNG to write (default: RESULT_forces.png)")
    args = parser.parse_args()
    out = args.out or os.path.splitext(args.result)[0] + "_forces.png"

    with h5py.File(args.result, "r") as f:
        if "forces" not in f:
            sys.exit(f"{args.result}: no /forces group (the run had no structures)")
        structures = names(f["forces"].attrs, "structures", f["forces"].keys())
        if args.obstacle:
            if args.obstacle not in structures:
                sys.exit(f"{args.result}: no structure '{args.obstacle}' "
                         f"(there are: {', '.join(structures)})")
            structures = [args.obstacle]
        data = list(panels(f["forces"], structures, args.faces))
    if not data:
        sys.exit(f"{args.result}: no structures in /forces")

    fig, axes = plt.subplots(len(data), 1, figsize=(9, 2.6 * len(data) + 0.6), sharex=True,
                             squeeze=False)
    for ax, (label, time, force, units) in zip(axes[:, 0], data):
        magnitude = np.linalg.norm(force, axis=1)
        ax.plot(time, magnitude, color="0.7", lw=2.5, label="$|F|$")
        for k, c in enumerate("xyz"):
            ax.plot(time, force[:, k], lw=0.9, label=f"$F_{c}$")
        title = label
        if len(time) and not np.all(np.isnan(magnitude)):
            i = int(np.nanargmax(magnitude))
            ax.plot(time[i], magnitude[i], "o", color="tab:red", label="peak")
            title += f": peak |F| = {magnitude[i]:.4g} {units} at t = {time[i]:.4g} s"
        ax.set_title(title, fontsize=9, loc="left")
        ax.set_ylabel(f"F [{units}]")
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", fontsize=8, ncol=5)
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(f"Forces on the structures: {os.path.basename(args.result)}", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(out)


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Prints a summary of a Surge results file: metadata, snapshots, particles, energy balance.

Usage: /usr/bin/python3 scripts/read_results.py results/<scene>/<scene>.h5
(Debian's python3-h5py; see docs/results-format.md for the layout.)
"""
import sys

import h5py


def text(value):
    return value.decode("utf-8", "replace").rstrip("\0") if isinstance(value, bytes) else str(value)


def main(path):
    with h5py.File(path, "r") as f:
        attrs = {k: text(v) if not hasattr(v, "shape") or v.shape == () else v for k, v in f.attrs.items()}
        print(f"file        {path}")
        for key in ("name", "version", "git_hash", "threads", "dimension", "cell_size", "start_time_utc"):
            print(f"{key:11s} {text(attrs.get(key, '?'))}")
        snaps = sorted(f["snapshots"].keys())
        print(f"snapshots   {len(snaps)}")
        if snaps:
            first, last = f["snapshots"][snaps[0]], f["snapshots"][snaps[-1]]
            print(f"particles   {first['position'].shape[0]} at t = {first.attrs['time']:.4g} s, "
                  f"{last['position'].shape[0]} at t = {last.attrs['time']:.4g} s")
        e = f["energy"]
        n = e["time"].shape[0]
        print(f"energy rows {n}")
        if n:
            for i, label in ((0, "first"), (n - 1, "last")):
                print(f"  {label:5s} t = {e['time'][i]:.4g} s: kinetic {e['kinetic'][i]:.6g} J, "
                      f"strain {e['strain'][i]:.6g} J, gravitational {e['gravitational'][i]:.6g} J, "
                      f"wall work {e['wall_work'][i]:.6g} J")
        if "timing" in f:
            t = f["timing"].attrs
            print(f"exit        {text(t['exit_status'])} after {int(t['steps'])} steps, "
                  f"{float(t['wall_seconds']):.2f} s wall")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])

#!/usr/bin/python3
"""Prints a summary of a Surge results file: metadata, snapshots, particles, energy balance.

Usage: /usr/bin/python3 scripts/read_results.py results/<scene>/<scene>.h5
(Debian's python3-h5py; the layout is described in docs/results-format.md.)
"""
import sys

import h5py


def text(value):
    """Decodes an HDF5 fixed-length string (bytes, UTF-8, null-padded)."""
    if isinstance(value, bytes):
        return value.decode("utf-8", "replace").rstrip("\0")
    return str(value)


def main(path):
    with h5py.File(path, "r") as f:
        print(f"{'file':15s} {path}")
        for key in ("name", "version", "git_hash", "scene_path", "command_line",
                    "start_time_utc", "threads", "dimension", "cell_size"):
            print(f"{key:15s} {text(f.attrs[key]) if key in f.attrs else '?'}")
        scene = text(f["metadata/scene"][()]) if "metadata/scene" in f else ""
        print(f"{'scene text':15s} {len(scene.splitlines())} lines")

        snaps = sorted(f["snapshots"].keys())
        print(f"{'snapshots':15s} {len(snaps)}")
        if snaps:
            first, last = f["snapshots"][snaps[0]], f["snapshots"][snaps[-1]]
            if "position" in first and "position" in last:
                print(f"{'particles':15s} {first['position'].shape[0]} at t = "
                      f"{first.attrs['time']:.6g} s, {last['position'].shape[0]} at t = "
                      f"{last.attrs['time']:.6g} s (step {int(last.attrs['step'])})")

        e = f["energy"]
        n = e["time"].shape[0]
        print(f"{'energy rows':15s} {n}")
        if n:
            for i, label in ((0, "first"), (n - 1, "last")):
                print(f"  {label:5s} t = {e['time'][i]:.6g} s: kinetic {e['kinetic'][i]:.6g} J, "
                      f"strain {e['strain'][i]:.6g} J, gravitational "
                      f"{e['gravitational'][i]:.6g} J, wall work {e['wall_work'][i]:.6g} J")
            # total - wall_work is conserved up to numerical dissipation.
            balance0 = e["total"][0] - e["wall_work"][0]
            balance1 = e["total"][n - 1] - e["wall_work"][n - 1]
            print(f"  total - wall work: {balance0:.6g} J -> {balance1:.6g} J "
                  f"(change {balance1 - balance0:.3g} J)")
            if "internal_work" in e:  # results from 2026-12-03 on
                # kinetic + gravitational + internal work - wall work (+ the initial strain
                # energy): conserved for every material up to numerical dissipation.
                b = [e["kinetic"][i] + e["gravitational"][i] + e["internal_work"][i]
                     - e["wall_work"][i] + e["strain"][0] for i in (0, n - 1)]
                print(f"  energy balance (internal work included): {b[0]:.6g} J -> {b[1]:.6g} J "
                      f"(plastic and viscous work {e['internal_work'][n - 1] - e['strain'][n - 1] + e['strain'][0]:.6g} J)")

        if "timing" in f:
            t = f["timing"].attrs
            print(f"{'exit':15s} {text(t['exit_status'])} after {int(t['steps'])} steps, "
                  f"{float(t['wall_seconds']):.2f} s wall")
        else:
            print(f"{'exit':15s} no /timing: the run did not close the file (killed?)")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])

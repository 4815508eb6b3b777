#!/usr/bin/python3
"""Compares the anti-locking options on the seed's dam break with barrier (Mast 2013 §6.1.2).

Runs scenes/dam_break_barrier_2d.yaml once per option (docs/antilocking.md, "Comparison on the
dam break with barrier"), then reads each result's barrier force (forces_barrier.csv, face x-)
and final particle pressure and writes:
  - a table (stdout, and <out>/antilocking_report.csv): wall time, peak barrier force (raw and
    smoothed), force noise after the impact, and the scatter of the particle pressure at the end
    about its local mean (pressure_scatter);
  - docs/plots/antilocking_barrier_force.png: the barrier force histories;
  - docs/plots/antilocking_barrier_pressure.png: the particle pressure at the end, per option.

Usage:
  /usr/bin/python3 scripts/antilocking_report.py [--surge build/surge] [--out results/antilocking_report]
      [--plots docs/plots] [--end 2.0] [--threads 1] [--set key=value ...] [--reuse]

Noise is RMS(F - F_avg) / mean(F) over t in [t_impact + 0.2 s, end], F_avg the centred moving
average over 0.1 s: the step-to-step scatter of the wall force, which the seed attributes to
locking and cell crossing (§7.4.3). The smoothed peak uses the same moving average.
"""
import argparse
import csv
import os
import subprocess
import sys
import time

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

OPTIONS = [  # label, antilocking map
    ("none", "{method: none}"),
    ("node", "{method: node}"),
    ("cell", "{method: cell}"),
    ("hybrid", "{method: hybrid}"),
    ("cell AS3CV", "{method: cell, approach: constant_volumetric}"),
    ("cell AS2", "{method: cell, approach: volumetric_deviatoric}"),
    ("smoothing", "{method: smoothing}"),
    ("smoothing total", "{method: smoothing, strain: total}"),
    ("node AS3CV", "{method: node, approach: constant_volumetric}"),
    ("node AS2 constant", "{method: node, approach: volumetric_deviatoric, fit: constant}"),
    ("node + stress", "{method: node, stress: true}"),
    ("cell + stress", "{method: cell, stress: true}"),
    ("hybrid + stress", "{method: hybrid, stress: true}"),
    ("cell AS2 + stress", "{method: cell, approach: volumetric_deviatoric, stress: true}"),
]
SCENE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "scenes",
                     "dam_break_barrier_2d.yaml")
RHO, G = 997.5, 9.81


def moving_average(t, f, window):
    """Centred moving average of f(t) over `window` seconds (uneven steps: by time)."""
    out = np.empty_like(f)
    lo = hi = 0
    csum = np.concatenate(([0.0], np.cumsum(f)))
    for i, ti in enumerate(t):
        while t[lo] < ti - window / 2:
            lo += 1
        while hi < len(t) and t[hi] <= ti + window / 2:
            hi += 1
        out[i] = (csum[hi] - csum[lo]) / (hi - lo)
    return out


def run(surge, out, label, antilocking, end, threads, extra, reuse):
    folder = os.path.join(out, label.replace(" ", "_"))
    stamp = os.path.join(folder, "report_wall_s.txt")
    if reuse and os.path.exists(stamp):
        return folder, float(open(stamp).read())
    cmd = [surge, "run", SCENE, "--force", "--threads", str(threads), "--out", folder,
           "--set", f"time.end={end}", "--set", f"materials.water.antilocking={antilocking}"]
    for s in extra:
        cmd += ["--set", s]
    start = time.time()
    proc = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = time.time() - start
    if proc.returncode != 0:
        sys.stderr.write(proc.stdout[-3000:])
        raise SystemExit(f"antilocking_report: {label}: surge exited {proc.returncode}")
    with open(stamp, "w") as fh:
        fh.write(f"{wall:.3f}\n")
    return folder, wall


def pressure_scatter(x, y, p, radius=0.375):
    """RMS over particles of p minus the mean p of the particles within `radius` (1.5 cells)
    of it, relative to rho g h0 (h0 = 2 m): the particle-to-particle noise (checkerboard) of the
    pressure field, whatever the flow does at large scale."""
    local = np.empty_like(p)
    for i0 in range(0, len(p), 512):
        dx = x[i0:i0 + 512, None] - x[None, :]
        dy = y[i0:i0 + 512, None] - y[None, :]
        near = dx * dx + dy * dy <= radius * radius
        local[i0:i0 + 512] = (near * p[None, :]).sum(axis=1) / near.sum(axis=1)
    return float(np.sqrt(np.mean((p - local) ** 2)) / (RHO * G * 2.0))


def analyse(folder):
    rows = list(csv.DictReader(open(os.path.join(folder, "forces_barrier.csv"))))
    t = np.array([float(r["time_s"]) for r in rows])
    f = np.array([float(r["x-_fx_N"]) for r in rows])  # the water pushes the barrier along +x
    with h5py.File(os.path.join(folder, "dam_break_barrier_2d.h5"), "r") as h5:
        snaps = h5["snapshots"]
        last = snaps[sorted(snaps.keys())[-1]]
        x = last["position"][:, 0]
        y = last["position"][:, 1]
        p = last["pressure"][:]
    return t, f, x, y, p


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--surge", default="build/surge")
    ap.add_argument("--out", default="results/antilocking_report")
    ap.add_argument("--plots", default="docs/plots")
    ap.add_argument("--end", type=float, default=2.0)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], help="extra scene override (key=value)")
    ap.add_argument("--reuse", action="store_true",
                    help="analyse the results of an earlier run in --out instead of running again")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    os.makedirs(args.plots, exist_ok=True)

    results = []
    for label, al in OPTIONS:
        folder, wall = run(args.surge, args.out, label, al, args.end, args.threads, args.set,
                           args.reuse)
        t, f, x, y, p = analyse(folder)
        results.append((label, al, wall, t, f, x, y, p))
        print(f"  ran {label:16s} {wall:6.1f} s", file=sys.stderr)

    base_wall = results[0][2]
    table = []
    for label, al, wall, t, f, x, y, p in results:
        touched = np.nonzero(np.abs(f) > 0)[0]
        t_impact = t[touched[0]] if len(touched) else float("nan")
        smooth = moving_average(t, f, 0.1)
        late = t >= t_impact + 0.2
        noise = (float(np.sqrt(np.mean((f[late] - smooth[late]) ** 2)) / np.mean(np.abs(f[late])))
                 if late.any() else float("nan"))
        scatter = pressure_scatter(x, y, p)
        table.append({
            "option": label, "antilocking": al, "wall_s": round(wall, 2),
            "time_vs_none": round(wall / base_wall, 3),
            "t_impact_s": round(float(t_impact), 4),
            "peak_N_per_m": round(float(np.max(f)), 1),
            "t_peak_s": round(float(t[np.argmax(f)]), 4),
            "peak_smoothed_N_per_m": round(float(np.max(smooth)), 1),
            "noise_rms_over_mean": round(noise, 4),
            "pressure_scatter_end": round(scatter, 4),
        })

    keys = list(table[0].keys())
    with open(os.path.join(args.out, "antilocking_report.csv"), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(table)
    print("| option | time / none | peak F [N/m] (t) | smoothed peak [N/m] | force noise | pressure scatter at end |")
    print("|---|---|---|---|---|---|")
    for r in table:
        print(f"| {r['option']} | {r['time_vs_none']:.2f} | {r['peak_N_per_m']:.0f} ({r['t_peak_s']:.2f} s) | "
              f"{r['peak_smoothed_N_per_m']:.0f} | {r['noise_rms_over_mean']:.3f} | {r['pressure_scatter_end']:.3f} |")

    fig, axes = plt.subplots(len(results), 1, figsize=(8, 1.6 * len(results)), sharex=True, sharey=True)
    for ax, (label, al, wall, t, f, x, y, p) in zip(axes, results):
        ax.plot(t, f / 1e3, lw=0.6, color="0.6", label="per step")
        ax.plot(t, moving_average(t, f, 0.1) / 1e3, lw=1.2, color="C0", label="0.1 s average")
        ax.set_ylabel("kN/m")
        ax.text(0.01, 0.85, label, transform=ax.transAxes, fontsize=9)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("t [s]")
    fig.suptitle("Dam break with barrier (Mast 2013 §6.1.2): barrier force, face x-")
    fig.tight_layout()
    fig.savefig(os.path.join(args.plots, "antilocking_barrier_force.png"), dpi=110)

    cols = 4
    rows_n = (len(results) + cols - 1) // cols
    fig, axes = plt.subplots(rows_n, cols, figsize=(3.3 * cols, 1.35 * rows_n + 0.9), sharex=True,
                             sharey=True, constrained_layout=True)
    vmax = RHO * G * 2.0
    for ax, (label, al, wall, t, f, x, y, p) in zip(axes.flat, results):
        sc = ax.scatter(x, y, c=p, s=2, cmap="viridis", vmin=0, vmax=vmax)
        ax.set_title(label, fontsize=9)
        ax.set_aspect("equal")
    for ax in list(axes.flat)[len(results):]:
        ax.axis("off")
    fig.colorbar(sc, ax=axes, shrink=0.9, label="particle pressure [Pa]")
    fig.suptitle(f"Particle pressure at t = {args.end} s")
    fig.savefig(os.path.join(args.plots, "antilocking_barrier_pressure.png"), dpi=110)
    print(f"antilocking_report: {os.path.join(args.out, 'antilocking_report.csv')}, "
          f"{args.plots}/antilocking_barrier_force.png, {args.plots}/antilocking_barrier_pressure.png",
          file=sys.stderr)


if __name__ == "__main__":
    main()

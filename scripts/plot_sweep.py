#!/usr/bin/python3
"""Plots the force summary of a parametric sweep over two of its parameters (docs/sweeps.md).

Usage:
  /usr/bin/python3 scripts/plot_sweep.py SWEEP.csv --x wc --y phi [--quantities f_pk f_ss ...]
                                         [--out PNG]
  /usr/bin/python3 scripts/plot_sweep.py SWEEP.csv --histories [--match REGEX] [--out PNG]

Reads <out>/sweep.csv of `surge sweep` (one row per case: the parameters, then the flattened
summary.json) and draws, for each quantity, a contour plot over the (x, y) plane (seed Figs
7.36-7.40, 7.44-7.46) when the completed cases form a full grid of at least 2 x 2 values, and
always the cuts: the quantity against x, one line per value of y (seed Figs 7.37-7.39).
Quantities (docs/forces.md; Mast 2013 eqs. 7.14, 7.18-7.19):

  f_pk     |analysis.peak.value|            peak force [kN]
  f_ss     analysis.steady_state.value      steady-state force [kN]
  c_pk     analysis.coefficients.c_pk       C_pk = f_pk / (rho0 v0^2 w_c H_b)
  c_ss     analysis.coefficients.c_ss
  r_pk     analysis.coefficients.r_pk       R_pk = f_pk / f_st(H_act) (7.19)
  r_ss     analysis.coefficients.r_ss
  r_pk_hb  analysis.coefficients.r_pk_hb    R_pk with H_b for H_act
  r_ss_hb  analysis.coefficients.r_ss_hb
  a_ratio_ss, h_act_ss, peak_to_steady      the coefficients of those names
  any other column of sweep.csv, by its full name

Default quantities: f_pk f_ss c_pk c_ss r_pk_hb r_ss_hb. Cases that are not completed, and
empty cells (a steady state that was not found), are left out; the title says how many.
Default output: sweep.png beside the CSV.

--histories instead draws the analysed force series of every completed case in one panel (seed
Fig. 7.34), each case's <case>/<scene>.h5 read with the structure, face and component of its
summary.json, the steady-state value drawn over its window where one was found; --match keeps
the cases whose name matches a regular expression (e.g. 'wc=3_'). Default output:
sweep_histories.png. Needs Debian's python3-matplotlib (and python3-h5py for --histories).
"""
import glob
import json
import re
import argparse
import csv
import os
import sys

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

QUANTITIES = {
    "f_pk": ("analysis.peak.value", 1e-3, "$f_{pk}$ [kN]"),
    "f_ss": ("analysis.steady_state.value", 1e-3, "$f_{ss}$ [kN]"),
    "c_pk": ("analysis.coefficients.c_pk", 1, "$C_{pk}$"),
    "c_ss": ("analysis.coefficients.c_ss", 1, "$C_{ss}$"),
    "r_pk": ("analysis.coefficients.r_pk", 1, "$R_{pk}$ (7.19, $H_{act}$)"),
    "r_ss": ("analysis.coefficients.r_ss", 1, "$R_{ss}$ (7.19, $H_{act}$)"),
    "r_pk_hb": ("analysis.coefficients.r_pk_hb", 1, "$R_{pk}$ with $H_b$"),
    "r_ss_hb": ("analysis.coefficients.r_ss_hb", 1, "$R_{ss}$ with $H_b$"),
    "a_ratio_ss": ("analysis.coefficients.a_ratio_ss", 1, "$A_{ratio}$ steady"),
    "h_act_ss": ("analysis.coefficients.h_act_ss", 1, "$H_{act}$ steady [m]"),
    "peak_to_steady": ("analysis.coefficients.peak_to_steady", 1, "$f_{pk} / f_{ss}$"),
}
DEFAULT = ["f_pk", "f_ss", "c_pk", "c_ss", "r_pk_hb", "r_ss_hb"]


def number(cell):
    try:
        return float(cell)
    except (TypeError, ValueError):
        return None


def histories(args):
    """The analysed force series of every completed case, with its steady state."""
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    import h5py
    from plot_forces import component  # the same scalar as surge forces
    folder = os.path.dirname(os.path.abspath(args.csv))
    with open(args.csv, newline="", encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r.get("status") == "completed"
                and (not args.match or re.search(args.match, r["case"]))]
    if not rows:
        sys.exit(f"{args.csv}: no completed case" + (f" matching '{args.match}'" if args.match else ""))
    fig, ax = plt.subplots(figsize=(9, 5))
    if len(rows) > 10:  # distinct colours for up to 20 cases
        ax.set_prop_cycle(color=plt.get_cmap("tab20").colors)
    label = ""
    for r in rows:
        case = os.path.join(folder, r["case"])
        results = glob.glob(os.path.join(case, "*.h5"))
        summary_path = os.path.join(case, "summary.json")
        if len(results) != 1 or not os.path.isfile(summary_path):
            print(f"{case}: skipped (no single .h5 with a summary.json)", file=sys.stderr)
            continue
        with open(summary_path, encoding="utf-8") as f:
            a = json.load(f).get("analysis")
        if a is None:
            continue
        with h5py.File(results[0], "r") as f:
            group = f["forces"][a["structure"]]
            series = group["faces"][a["face"]] if a.get("face") else group
            time, force = group["time"][:], series["force"][:]
        x = component(force, a["component"], a.get("face", ""))
        line, = ax.plot(time, x / 1e3, lw=0.9, label=r["case"])
        ss = a["steady_state"]
        if ss["status"] != "none" and ss["value"] is not None:
            ax.hlines(ss["value"] / 1e3, ss["t0"], ss["t1"], color=line.get_color(), lw=2.5,
                      alpha=0.6)
        label = a["structure"] + (f"/{a['face']}" if a.get("face") else "") + f" {a['component']}"
    ax.set_xlabel("time [s]")
    ax.set_ylabel("force [kN]")
    ax.set_title(f"{label}; thick: steady state over its window", fontsize=9, loc="left")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    fig.suptitle(os.path.basename(folder), fontsize=10)
    fig.tight_layout()
    out = args.out or os.path.join(folder, "sweep_histories.png")
    fig.savefig(out, dpi=110)
    print(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("csv", help="the sweep's sweep.csv")
    parser.add_argument("--x", help="parameter column on the horizontal axis")
    parser.add_argument("--y", help="parameter column: contour axis / one cut each")
    parser.add_argument("--histories", action="store_true",
                        help="the force series of every case in one panel instead")
    parser.add_argument("--match", metavar="REGEX",
                        help="with --histories: only the cases whose name matches")
    parser.add_argument("--quantities", nargs="+", default=DEFAULT, metavar="Q",
                        help=f"what to plot (default: {' '.join(DEFAULT)})")
    parser.add_argument("--out", help="PNG to write (default: sweep.png beside the CSV)")
    args = parser.parse_args()
    if args.histories:
        histories(args)
        return
    if not args.x or not args.y:
        parser.error("--x and --y are required (or --histories)")
    out = args.out or os.path.join(os.path.dirname(os.path.abspath(args.csv)), "sweep.png")

    with open(args.csv, newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{args.csv}: no cases")
    columns = rows[0].keys()
    for axis in (args.x, args.y):
        if axis not in columns:
            sys.exit(f"{args.csv}: no column '{axis}' (parameters come after 'case'; columns: "
                     f"{', '.join(list(columns)[:8])}, ...)")
    done = [r for r in rows if r.get("status") == "completed"]
    if not done:
        sys.exit(f"{args.csv}: no completed case ({len(rows)} cases)")
    specs = []
    for q in args.quantities:
        column, scale, label = QUANTITIES.get(q, (q, 1, q))
        if column not in columns:
            sys.exit(f"{args.csv}: no column '{column}' for quantity '{q}'")
        specs.append((q, column, scale, label))

    x = np.array([number(r[args.x]) for r in done], dtype=float)
    y = np.array([number(r[args.y]) for r in done], dtype=float)
    if np.isnan(x).any() or np.isnan(y).any():
        sys.exit(f"{args.csv}: '{args.x}' and '{args.y}' must be numbers in every completed case")
    xs, ys = np.unique(x), np.unique(y)

    fig, axes = plt.subplots(len(specs), 2, figsize=(10, 3.0 * len(specs) + 0.6), squeeze=False)
    for (q, column, scale, label), (cax, lax) in zip(specs, axes):
        v = np.array([number(r[column]) if number(r[column]) is not None else np.nan
                      for r in done], dtype=float)
        if q == "f_pk":
            v = np.abs(v)  # the signed peak sample: its size is the peak force
        v = v * scale
        missing = int(np.isnan(v).sum())
        # Contours need every (x, y) of the grid once: pivot, else say why there are none.
        grid = np.full((len(ys), len(xs)), np.nan)
        for xi, yi, vi in zip(x, y, v):
            grid[np.searchsorted(ys, yi), np.searchsorted(xs, xi)] = vi
        if len(xs) >= 2 and len(ys) >= 2 and not np.isnan(grid).any() and len(done) == grid.size:
            cs = cax.contourf(xs, ys, grid, levels=12, cmap="viridis")
            cax.contour(xs, ys, grid, levels=cs.levels, colors="k", linewidths=0.3)
            fig.colorbar(cs, ax=cax, label=label)
            cax.plot(x, y, "k.", ms=3)
        else:
            cax.plot(x, y, "k.", ms=5)
            cax.text(0.5, 0.5, "no contour: the cases with a value\ndo not fill a 2 x 2 grid or more",
                     ha="center", va="center", transform=cax.transAxes, fontsize=8)
        cax.set_xlabel(args.x)
        cax.set_ylabel(args.y)
        cax.set_title(label + (f" ({missing} of {len(v)} without a value)" if missing else ""),
                      fontsize=9, loc="left")
        for yi in ys:
            sel = (y == yi) & ~np.isnan(v)
            if sel.any():
                order = np.argsort(x[sel])
                lax.plot(x[sel][order], v[sel][order], "o-", ms=4, label=f"{args.y} = {yi:g}")
        lax.set_xlabel(args.x)
        lax.set_ylabel(label)
        lax.grid(alpha=0.3)
        if lax.lines:
            lax.legend(fontsize=7)
    fig.suptitle(f"{os.path.basename(os.path.dirname(os.path.abspath(args.csv)))}: "
                 f"{len(done)} of {len(rows)} cases completed", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(out)


if __name__ == "__main__":
    main()

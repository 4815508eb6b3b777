#!/usr/bin/python3
"""Plots the Taylor-bar histories written by tests/verification/taylor_bar_test.cpp.

Usage:
  SURGE_TAYLOR_CSV=docs/data SURGE_TAYLOR_FULL=1 build/tests/verification/taylor_bar_test
  /usr/bin/python3 scripts/plot_taylor_bar.py [csv_dir] [out.png]

Defaults: csv_dir = docs/data, out = docs/plots/taylor_bar.png. Left: the seed bar's H/H0 and
R/R0 against T = t/t_f (Mast 2013 §7.1, eq. 7.1). Right: the copper bar's L/L0 and R/R0 against
t [us], with the published final values marked (docs/taylor_bar.md gives the sources).
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# Published final shape of the copper benchmark (L0 = 32.4 mm, R0 = 3.2 mm, 227 m/s): reference
# FE solutions, not an experiment (docs/taylor_bar.md, "Copper comparison").
COPPER_L0_MM, COPPER_R0_MM = 32.4, 3.2
COPPER_FINAL_L_MM = (21.42, 21.47)
COPPER_FINAL_R_MM = (7.0, 7.1)


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def main():
    csv_dir = sys.argv[1] if len(sys.argv) > 1 else "docs/data"
    out = sys.argv[2] if len(sys.argv) > 2 else "docs/plots/taylor_bar.png"
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 4))

    for name, style, label in (("taylor_bar_seed_full.csv", "-", "h = 1 cm, 27 PPC"),
                               ("taylor_bar_seed_coarse.csv", ":", "h = 2 cm, 8 PPC")):
        path = os.path.join(csv_dir, name)
        if not os.path.exists(path):
            continue
        d = read(path)
        ax1.plot(d["T"], d["H_bar"], "b" + style, label="H/H0, " + label)
        ax1.plot(d["T"], d["R_bar"], "r" + style, label="R/R0, " + label)
    ax1.set_xlabel("T = t / t_f")
    ax1.set_ylabel("H/H0, R/R0")
    ax1.set_title("Seed Taylor bar (Mast 2013 Table 7.1), J2, no anti-locking", fontsize=9)
    ax1.grid(True, alpha=0.3)
    ax1.legend(fontsize=7)

    for name, style, label in (("taylor_bar_copper_full.csv", "-", "h = 0.4 mm, 27 PPC"),
                               ("taylor_bar_copper_coarse.csv", ":", "h = 0.8 mm, 8 PPC")):
        path = os.path.join(csv_dir, name)
        if not os.path.exists(path):
            continue
        d = read(path)
        ax2.plot(d["t_us"], d["L_over_L0"], "b" + style, label="L/L0, " + label)
        ax2.plot(d["t_us"], d["R_over_R0"], "r" + style, label="R/R0 (centroid), " + label)
        ax2.plot(d["t_us"], d["R_outer_over_R0"], "g" + style, label="R/R0 (outer), " + label)
    for lo, hi, ref, color, text in ((*COPPER_FINAL_L_MM, COPPER_L0_MM, "b", "published L_f"),
                                     (*COPPER_FINAL_R_MM, COPPER_R0_MM, "k", "published R_f")):
        ax2.axhspan(lo / ref, hi / ref, color=color, alpha=0.25)
        ax2.axhline(0.5 * (lo + hi) / ref, color=color, lw=0.8, ls="--")
        ax2.text(1, 0.5 * (lo + hi) / ref + 0.02, text, color=color, fontsize=7)
    ax2.set_xlabel("t [us]")
    ax2.set_ylabel("L/L0, R/R0")
    ax2.set_title("Copper Taylor bar (L0 = 32.4 mm, R0 = 3.2 mm, 227 m/s)", fontsize=9)
    ax2.grid(True, alpha=0.3)
    ax2.legend(fontsize=7)

    fig.tight_layout()
    os.makedirs(os.path.dirname(out) or ".", exist_ok=True)
    fig.savefig(out, dpi=90)
    print("wrote", out)


if __name__ == "__main__":
    main()

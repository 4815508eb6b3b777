#!/usr/bin/python3
"""Plots the simple-shear and biaxial curves written by tests/verification/soil_paths_test.cpp.

Usage:
  mkdir -p /tmp/soil && SURGE_SOIL_PATHS_CSV=/tmp/soil build/tests/verification/soil_paths_test
  /usr/bin/python3 scripts/plot_soil_paths.py [csv_dir] [out_dir]

Defaults: csv_dir = /tmp/soil, out_dir = docs/plots. Writes soil_simple_shear.png (sigma_12 and
sigma_33 vs eps_12, eps_v vs eps_12, p-q path) and soil_biaxial.png (q vs -eps_22, eps_v vs
-eps_22, p-q path) for the models whose CSV exists: DP (modified Drucker-Prager), MN-DP
(Matsuoka-Nakai yield, DP potential) and MN (Matsuoka-Nakai). Mast (2013) Figs. 3.8-3.10;
docs/soil_paths.md.
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MODELS = (("dp", "DP", "-", "tab:blue"),
          ("mn_dp", "MN with DP G", "--", "tab:orange"),
          ("mn", "MN", ":", "tab:green"))


def read(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def curves(csv_dir, test):
    for key, label, style, color in MODELS:
        path = os.path.join(csv_dir, f"{test}_{key}.csv")
        if os.path.exists(path):
            yield read(path), dict(label=label, linestyle=style, color=color)


def kpa(values):
    return [v / 1e3 for v in values]


def simple_shear(csv_dir, out):
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.8))
    for d, style in curves(csv_dir, "simple_shear"):
        axes[0].plot(d["strain"], kpa(d["sigma12_pa"]), **style)
        axes[1].plot(d["strain"], kpa(d["sigma33_pa"]), **style)
        axes[2].plot(d["strain"], d["eps_v"], **style)
        axes[3].plot([-p for p in kpa(d["p_pa"])], kpa(d["q_pa"]), **style)
    labels = ((r"$\varepsilon_{12}$", r"$\sigma_{12}$ [kPa]", "(a) shear stress"),
              (r"$\varepsilon_{12}$", r"$\sigma_{33}$ [kPa]", "(b) out-of-plane stress"),
              (r"$\varepsilon_{12}$", r"$\varepsilon_v = \ln J$", "(c) volume (> 0 dilation)"),
              (r"$-p$ [kPa]", r"$q$ [kPa]", "(d) p-q path"))
    finish(fig, axes, labels, "Simple shear, sigma_11 = sigma_22 = -150 kPa, eps_33 = 0", out)


def biaxial(csv_dir, out):
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for d, style in curves(csv_dir, "biaxial"):
        axes[0].plot(d["strain"], kpa(d["q_pa"]), **style)
        axes[1].plot(d["strain"], d["eps_v"], **style)
        axes[2].plot([-p for p in kpa(d["p_pa"])], kpa(d["q_pa"]), **style)
    axes[0].axhline(155.94, color="grey", linewidth=0.8)
    axes[0].annotate("q_cs = 150 w/(1 - w/3) = 155.9 kPa", (0.05, 160), fontsize=8)
    labels = ((r"$-\varepsilon_{22}$", r"$q$ [kPa]", "(a) deviator stress"),
              (r"$-\varepsilon_{22}$", r"$\varepsilon_v = \ln J$", "(b) volume (> 0 dilation)"),
              (r"$-p$ [kPa]", r"$q$ [kPa]", "(c) p-q path"))
    finish(fig, axes, labels, "Biaxial compression, sigma_11 = sigma_33 = -150 kPa", out)


def finish(fig, axes, labels, title, out):
    for ax, (xl, yl, t) in zip(axes, labels):
        ax.set_xlabel(xl)
        ax.set_ylabel(yl)
        ax.set_title(t, fontsize=10)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title + " (dense sand, Table 3.5 i; Mast 2013 §3.8)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=80)
    print("wrote", out, os.path.getsize(out), "bytes")


def main():
    csv_dir = sys.argv[1] if len(sys.argv) > 1 else "/tmp/soil"
    out_dir = sys.argv[2] if len(sys.argv) > 2 else "docs/plots"
    simple_shear(csv_dir, os.path.join(out_dir, "soil_simple_shear.png"))
    biaxial(csv_dir, os.path.join(out_dir, "soil_biaxial.png"))


if __name__ == "__main__":
    main()

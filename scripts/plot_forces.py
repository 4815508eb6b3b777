#!/usr/bin/python3
"""Plots the per-step force series of a Surge run (docs/results-format.md, "Force series").

Usage:
  /usr/bin/python3 scripts/plot_forces.py RESULT.h5 [--obstacle NAME] [--faces] [--out PNG]
  /usr/bin/python3 scripts/plot_forces.py RESULT.h5 --analysis [SUMMARY.json] [--out PNG]

One panel per structure (and per face with --faces): F_x, F_y, F_z and |F| against time, with
the peak of |F| marked (the first row that reaches it, as the writer's peak_force attribute).
Default output: RESULT_forces.png beside the .h5.

--analysis draws what `surge forces` analysed (docs/forces.md), read from summary.json (default:
the one beside the .h5): the analysed structure/face/component against time with its peak, the
steady-state window and value f_ss marked (or the stretch the plateau detector measured when it
found none), and below it the contact height H_act = A_act / w_c (Mast 2013 eq. 7.15, seed Figs
7.41-7.42) and the area ratio A_ratio = A_act / (w_c H_b) (eq. 7.16, Fig. 7.43) of that face
against time, with H_b drawn for comparison. Default output: RESULT_analysis.png.
Needs Debian's python3-h5py and matplotlib.
"""
import json
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


def component(force, name, face):
    """The analysed scalar of an n x 3 force series, as surge forces defines it (docs/forces.md):
    x|y|z, magnitude, or normal = F . (-n) for an axis face "x-" ... "z+" (push on the face > 0)."""
    if name in ("x", "y", "z"):
        return force[:, "xyz".index(name)]
    if name == "normal":
        if len(face) != 2 or face[0] not in "xyz" or face[1] not in "+-":
            sys.exit(f"component 'normal' needs an axis face, not '{face}'")
        sign = 1.0 if face[1] == "+" else -1.0  # outward normal n = sign e_axis
        return -sign * force[:, "xyz".index(face[0])]
    return np.linalg.norm(force, axis=1)


def moving_average(time, dt, x, width):
    """dt-weighted mean over |t_j - t_k| <= width/2, truncated at the ends (docs/forces.md; the
    seed's moving average for a constant dt). Without the impulse rescaling of the steady-state
    average, which changes it by a constant factor close to 1; drawn only as a guide."""
    if width <= 0 or len(x) == 0:
        return x
    cw = np.concatenate([[0.0], np.cumsum(dt * x)])
    cd = np.concatenate([[0.0], np.cumsum(dt)])
    lo = np.searchsorted(time, time - width / 2, side="left")
    hi = np.searchsorted(time, time + width / 2, side="right")
    return (cw[hi] - cw[lo]) / (cd[hi] - cd[lo])


def plot_analysis(args):
    """The analysed series with peak and steady state, and the contact height and area ratio."""
    summary_path = args.analysis
    if summary_path == "auto":
        summary_path = os.path.join(os.path.dirname(os.path.abspath(args.result)), "summary.json")
    if not os.path.isfile(summary_path):
        sys.exit(f"{summary_path}: no such file (write it with: surge forces {args.result} --json)")
    with open(summary_path, encoding="utf-8") as f:
        summary = json.load(f)
    a = summary.get("analysis")
    if a is None:
        sys.exit(f"{summary_path}: no 'analysis' (the run had no structures)")
    structure, face, comp = a["structure"], a.get("face", ""), a["component"]
    with h5py.File(args.result, "r") as f:
        if "forces" not in f or structure not in f["forces"]:
            sys.exit(f"{args.result}: no force series for structure '{structure}'")
        group = f["forces"][structure]
        time, dt = group["time"][:], group["dt"][:]
        series = group["faces"][face] if face else group
        force, area = series["force"][:], series["contact_area"][:]
        unit = text(series["force"].attrs.get("units", "N"))
    x = component(force, comp, face)
    label = f"{structure}" + (f"/{face}" if face else "") + f" {comp}"
    ss, ref, coef = a["steady_state"], a["reference"], a["coefficients"]

    fig, (ax, bx) = plt.subplots(2, 1, figsize=(9, 7), sharex=True,
                                 gridspec_kw={"height_ratios": [3, 2]})
    ax.plot(time, x / 1e3, color="0.6", lw=0.8, label="raw")
    avg = moving_average(time, dt, x, ss.get("average") or 0)
    ax.plot(time, avg / 1e3, color="tab:blue", lw=1.4,
            label=f"moving average {ss.get('average', 0):g} s")
    pk = a["peak"]
    if pk["time"] is not None:
        ax.plot(pk["time"], pk["value"] / 1e3, "o", color="tab:red",
                label=f"peak $f_{{pk}}$ = {abs(pk['value']) / 1e3:.4g} k{unit} "
                      f"at {pk['time']:.3g} s")
    if ss.get("t0") is not None and ss.get("t1") is not None:
        found = ss["status"] != "none"
        ax.axvspan(ss["t0"], ss["t1"], color="tab:green" if found else "tab:orange", alpha=0.15,
                   label=("steady-state window" if found else
                          "final stretch (no plateau: shorter than min_window)"))
        level = ss["value"] if found else ss.get("mean")
        if level is not None:
            ax.hlines(level / 1e3, ss["t0"], ss["t1"], color="tab:green" if found else "tab:orange",
                      lw=2.2, label=(f"$f_{{ss}}$ = {level / 1e3:.4g} k{unit}" if found else
                                     f"stretch mean {level / 1e3:.4g} k{unit}"))
    info = []
    for key, name in (("c_pk", "C_pk"), ("c_ss", "C_ss"), ("r_pk_hb", "R_pk,Hb"),
                      ("r_ss_hb", "R_ss,Hb"), ("r_pk", "R_pk"), ("r_ss", "R_ss")):
        if coef.get(key) is not None:
            info.append(f"{name} = {coef[key]:.3g}")
    ax.set_title(f"{label}: " + ", ".join(info), fontsize=9, loc="left")
    ax.set_ylabel(f"force [k{unit}]")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)

    width, height = ref.get("width"), ref.get("height")
    if width:
        # H_act = A_act / w_c (7.15); A_ratio = A_act / (w_c H_b) (7.16).
        bx.plot(time, area / width, color="tab:purple", lw=1.0, label="$H_{act} = A_{act} / w_c$")
        bx.set_ylabel("contact height [m]")
        if height:
            bx.axhline(height, color="k", ls="--", lw=0.8, label=f"$H_b$ = {height:g} m")
            rx = bx.twinx()
            rx.plot(time, area / (width * height), color="tab:brown", lw=0.8, alpha=0.7)
            rx.set_ylabel("$A_{ratio} = A_{act} / (w_c H_b)$", color="tab:brown")
            lo, hi = bx.get_ylim()
            rx.set_ylim(lo / height, hi / height)  # the same curve scale: one axis reads both
    else:
        bx.plot(time, area, color="tab:purple", lw=1.0, label="$A_{act}$")
        bx.set_ylabel("contact area [m$^2$]")
    bx.set_title("contact on " + label.rsplit(" ", 1)[0] + " (node count h$^{d-1}$: as coarse as the"
                 " grid, docs/forces.md)", fontsize=9, loc="left")
    bx.grid(alpha=0.3)
    bx.legend(loc="upper right", fontsize=8)
    bx.set_xlabel("time [s]")
    fig.suptitle(f"Force analysis: {os.path.basename(args.result)}", fontsize=10)
    fig.tight_layout()
    out = args.out or os.path.splitext(args.result)[0] + "_analysis.png"
    fig.savefig(out, dpi=120)
    print(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("result", help="the run's .h5 file")
    parser.add_argument("--obstacle", help="plot only this structure (e.g. domain)")
    parser.add_argument("--faces", action="store_true", help="also plot every face")
    parser.add_argument("--analysis", nargs="?", const="auto", metavar="SUMMARY.json",
                        help="plot the analysed series, peak, steady state and contact height "
                             "from summary.json (default: the one beside the .h5)")
    parser.add_argument("--out", help="PNG to write (default: RESULT_forces.png, "
                                      "RESULT_analysis.png with --analysis)")
    args = parser.parse_args()
    if args.analysis:
        plot_analysis(args)
        return
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

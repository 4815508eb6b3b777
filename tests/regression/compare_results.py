#!/usr/bin/python3
"""Compares two Surge results folders bit for bit (tests/regression/restart_test.sh).

Usage: compare_results.py DIR_A DIR_B NAME [--tolerance REL] [--ignore-attr KEY ...]

Compares <dir>/<NAME>.h5 (every numeric dataset by its bytes, every attribute except the
wall-clock ones in /timing and the root's command_line and start_time_utc), every CSV and the .xmf of DIR_A byte for byte with DIR_B's, and
summary.json (less its "result" path). Prints one line per difference and exits 1 if any.
With --tolerance REL the float datasets only need max |a - b| <= REL * max |a| (shapes and
integer datasets still exactly); the largest relative difference is printed.
"""
import argparse
import filecmp
import json
import os
import sys

import h5py
import numpy as np


def datasets(group, path=""):
    for key in group:
        obj = group[key]
        p = f"{path}/{key}"
        if isinstance(obj, h5py.Group):
            yield from datasets(obj, p)
        else:
            yield p


def attributes(f):
    out = {}

    def visit(name, obj):
        for key, value in obj.attrs.items():
            out[f"{name}@{key}"] = np.asarray(value).tobytes()

    for key, value in f.attrs.items():
        out[f"@{key}"] = np.asarray(value).tobytes()
    f.visititems(visit)
    return out


def strip_result(doc):
    if isinstance(doc, dict):
        return {k: strip_result(v) for k, v in doc.items() if k != "result"}
    if isinstance(doc, list):
        return [strip_result(v) for v in doc]
    return doc


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("name")
    ap.add_argument("--tolerance", type=float, default=None)
    ap.add_argument("--ignore-attr", action="append", default=[],
                    help="attribute key to skip, e.g. @threads (repeatable)")
    args = ap.parse_args()
    diffs = []
    worst = 0.0
    with h5py.File(f"{args.a}/{args.name}.h5", "r") as fa, h5py.File(f"{args.b}/{args.name}.h5", "r") as fb:
        da, db = set(datasets(fa)), set(datasets(fb))
        for p in sorted(da ^ db):
            diffs.append(f"{p}: only in one result")
        numeric = 0
        for p in sorted(da & db):
            x, y = fa[p][()], fb[p][()]
            if not (isinstance(x, np.ndarray) and x.dtype.kind in "fiu"):
                if x != y:
                    diffs.append(f"{p}: differs")
                continue
            numeric += 1
            if x.shape != y.shape:
                diffs.append(f"{p}: shape {x.shape} vs {y.shape}")
            elif x.tobytes() != y.tobytes():
                if args.tolerance is not None and x.dtype.kind == "f":
                    scale = max(float(np.nanmax(np.abs(x))) if x.size else 0.0, 1e-300)
                    rel = float(np.nanmax(np.abs(x - y))) / scale
                    worst = max(worst, rel)
                    if not rel <= args.tolerance:
                        diffs.append(f"{p}: relative difference {rel:.3g}")
                else:
                    rows = np.nonzero((x != y).reshape(len(x), -1).any(axis=1))[0]
                    diffs.append(f"{p}: differs from row {rows[0] if len(rows) else '?'}")
        aa, ab = attributes(fa), attributes(fb)
        for key in sorted(set(aa) | set(ab)):
            if key.startswith("timing@") or key in ("@command_line", "@start_time_utc") \
                    or key in args.ignore_attr:
                continue  # wall-clock seconds of the stages; how and when the run was started
            if aa.get(key) != ab.get(key):
                if args.tolerance is not None and key.startswith("forces/"):
                    continue  # peak and impulse follow the series checked above
                diffs.append(f"attribute {key}: differs")
    files = sorted(f for f in os.listdir(args.a) if f.endswith((".csv", ".xmf")))
    for f in files:
        if not os.path.exists(f"{args.b}/{f}"):
            diffs.append(f"{f}: missing in {args.b}")
        elif args.tolerance is None and not filecmp.cmp(f"{args.a}/{f}", f"{args.b}/{f}", shallow=False):
            diffs.append(f"{f}: differs")
    with open(f"{args.a}/summary.json") as fa, open(f"{args.b}/summary.json") as fb:
        if args.tolerance is None and strip_result(json.load(fa)) != strip_result(json.load(fb)):
            diffs.append("summary.json: differs")
    print(f"{numeric} numeric datasets, {len(aa)} attributes, {len(files)} CSV/XMF files compared;"
          f" largest relative difference {worst:.3g}")
    for d in diffs[:20]:
        print("DIFF", d)
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())

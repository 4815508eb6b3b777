#!/usr/bin/python3
"""Checks the files of a run killed at an arbitrary moment (tests/regression/kill9_test.sh).

Usage: check_killed_files.py OUT_DIR NAME

- Every checkpoint under a final name (OUT_DIR/checkpoints/NAME_step_N.h5) is whole: it opens,
  its root attribute `format` is surge-checkpoint, and every dataset reads in full. `.tmp` files
  (a checkpoint being written when the process died) are counted, not opened: --restart and the
  listing ignore them.
- The result OUT_DIR/NAME.h5, if present, opens; every snapshot dataset that OUT_DIR/NAME.xmf
  lists exists with the dimensions the .xmf gives and reads in full; every dataset of /energy,
  /forces and /rigid reads in full (all rows up to the last flush).
Prints one summary line; exits 1 with the reason on the first problem.
"""
import os
import re
import sys

import h5py


def fail(msg):
    print(f"FAIL {msg}")
    sys.exit(1)


def read_all(group, where):
    """Reads every dataset below `group`; returns how many."""
    count = 0

    def visit(name, obj):
        nonlocal count
        if isinstance(obj, h5py.Dataset):
            try:
                obj[()]
            except Exception as e:  # noqa: BLE001 - any read error is the finding
                fail(f"{where}: dataset {obj.name} does not read: {e}")
            count += 1

    group.visititems(visit)
    return count


def main():
    out, name = sys.argv[1], sys.argv[2]
    ck_dir = os.path.join(out, "checkpoints")
    whole, tmp = 0, 0
    if os.path.isdir(ck_dir):
        for f in sorted(os.listdir(ck_dir)):
            p = os.path.join(ck_dir, f)
            if f.endswith(".tmp"):
                tmp += 1
                continue
            if not re.fullmatch(re.escape(name) + r"_step_\d{9}\.h5", f):
                fail(f"unexpected file in checkpoints/: {f}")
            try:
                with h5py.File(p, "r") as h:
                    fmt = h.attrs.get("format")
                    fmt = fmt.decode() if isinstance(fmt, bytes) else str(fmt)
                    if fmt != "surge-checkpoint":
                        fail(f"{p}: format attribute is {fmt!r}")
                    if read_all(h, p) == 0:
                        fail(f"{p}: no datasets")
            except OSError as e:
                fail(f"checkpoint {p} does not open: {e}")
            whole += 1

    h5 = os.path.join(out, name + ".h5")
    xmf = os.path.join(out, name + ".xmf")
    listed, series = 0, 0
    if os.path.exists(h5):
        items = []
        if os.path.exists(xmf):
            text = open(xmf).read()
            items = re.findall(r'<DataItem Dimensions="([0-9 ]+)"[^>]*>[^:<]+:(/snapshots/[^<]+)</DataItem>', text)
            listed = len(set(re.findall(r"/snapshots/([^/<]+)/", text)))
        try:
            with h5py.File(h5, "r") as h:
                for dims, path in items:
                    if path not in h:
                        fail(f"{h5}: {path} is listed in the .xmf but absent")
                    shape = tuple(int(d) for d in dims.split())
                    d = h[path]
                    if d.shape != shape:
                        fail(f"{h5}: {path} has shape {d.shape}, the .xmf says {shape}")
                    d[()]
                for g in ("energy", "forces", "rigid"):
                    if g in h:
                        series += read_all(h[g], f"{h5}/{g}")
        except OSError as e:
            fail(f"result {h5} does not open: {e}")
    state = "present" if os.path.exists(h5) else "absent"
    print(f"checkpoints: {whole} whole, {tmp} .tmp ignored; result {state}: {listed} snapshots "
          f"listed and readable, {series} series datasets readable")


if __name__ == "__main__":
    main()

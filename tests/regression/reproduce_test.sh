#!/usr/bin/env bash
# Reproducibility from the result file alone (issue 9, item 4; ctest label regression): a run of
# the small dam break against a barrier (tests/data/scenes/dam_barrier_small_2d.yaml) on 2 threads records the scene verbatim (/metadata/scene), the resolved scene, version, git hash
# and thread count; the scene text taken back out of that file and run on 1 thread gives the same
# result bit for bit (every numeric dataset, the force series, CSVs, .xmf, summary.json; only the
# thread count, the scene path, the command line and wall-clock attributes may differ).
# Usage: reproduce_test.sh <surge binary> <source dir>.
set -u
surge=$1
src=$2
. "$src/tests/support/cli_checks.sh"
compare="/usr/bin/python3 $src/tests/regression/compare_results.py"

cp "$src/tests/data/scenes/dam_barrier_small_2d.yaml" "$work/dam.yaml"
expect first_run 0 'completed' -- "$surge" run "$work/dam.yaml" --out "$work/a" --threads 2 --progress quiet
/usr/bin/python3 - "$work/a/dam_barrier.h5" "$work/from_file.yaml" > "$work/meta.txt" <<'PY'
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    text = f["metadata/scene"][()]
    text = text.decode() if isinstance(text, bytes) else str(text)
    open(sys.argv[2], "w").write(text)
    for key in ("version", "git_hash", "threads"):
        v = f.attrs[key]
        print(key, v.decode() if isinstance(v, bytes) else v)
    print("resolved", "yes" if "metadata/resolved" in f else "no")
PY
if cmp -s "$work/dam.yaml" "$work/from_file.yaml" && grep -q "^threads 2$" "$work/meta.txt" \
  && grep -q "^resolved yes$" "$work/meta.txt" && grep -q "^git_hash ." "$work/meta.txt" \
  && grep -q "^version ." "$work/meta.txt"; then
  ok "metadata"
else
  bad "metadata: scene text or attributes missing"; cat "$work/meta.txt"
fi
expect rerun_from_file 0 'completed' -- "$surge" run "$work/from_file.yaml" --out "$work/b" --threads 1 --progress quiet
if $compare "$work/a" "$work/b" dam_barrier --ignore-attr @threads --ignore-attr @scene_path > "$work/cmp.txt" \
  && grep -Eq "^[1-9][0-9]* numeric datasets" "$work/cmp.txt"; then
  ok "bitwise_from_file"
else
  bad "bitwise_from_file"; head -8 "$work/cmp.txt"
fi
finish reproduce

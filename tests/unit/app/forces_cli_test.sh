#!/usr/bin/env bash
# End-to-end checks of `surge forces` and <out>/summary.json (issue #6; docs/forces.md): a small
# 2-D block hits a wall; summary.json exists, `surge forces --json` prints the same document, and
# its numbers agree with the force series in the .h5 (peak, time, impulse, the face's normal
# component, C_pk and R_pk by hand); the table; errors for a missing file, a non-HDF5 file, a
# foreign HDF5 file, an unknown structure and an unknown face. (ctest label unit)
# Usage: forces_cli_test.sh <surge binary> <source dir>
set -u
surge=$1
src=$2
. "$(dirname "$0")/../../support/cli_checks.sh"
py=/usr/bin/python3


check() {  # check <name> <command...>: passes when the command exits 0
  local name=$1
  shift
  local out
  if out=$("$@" 2>&1); then
    echo "ok   $name"; pass=$((pass + 1))
  else
    echo "FAIL $name"; echo "$out" | tail -8; fail=$((fail + 1))
  fi
}

cat > "$work/fa.yaml" <<'YAML'
name: fa
dimension: 2
time: {end: 0.4}
gravity: [0, -9.81]
grid: {cell_size: 0.02}
domain: {min: [0, 0], max: [1, 0.5], walls: {x-: slip, y-: slip}}
materials:
  m: {model: neo_hookean, density: 1000, bulk_modulus: 1.0e6, shear_modulus: 1.0e5}
bodies:
  - {name: b, material: m, region: {box: {min: [0.1, 0.0], max: [0.3, 0.1]}}, velocity: [1, 0]}
obstacles:
  - {name: wall, shape: {box: {min: [0.5, -0.1], max: [0.6, 0.6]}}}
analysis:
  structure: wall
  face: x-
  reference: {height: 0.1, k0: 0.5}
  smoothing: {moving_average: 0.01}
  steady_state: {min_window: 0.05}
YAML
out="$work/out"
expect run_prints_analysis 0 'force analysis: wall face x-, component normal' -- "$surge" run "$work/fa.yaml" --out "$out" --progress quiet
if [ -s "$out/summary.json" ]; then echo "ok   summary_json_exists"; pass=$((pass + 1)); else echo "FAIL summary_json_exists"; fail=$((fail + 1)); fi
"$surge" forces "$out/fa.h5" --json > "$work/forces.json" 2> "$work/forces.err"
check forces_json_equals_summary diff "$out/summary.json" "$work/forces.json"
expect forces_table 0 'C_pk .*R_pk' -- "$surge" forces "$out/fa.h5"
expect forces_table_faces 0 '^  x- ' -- "$surge" forces "$out/fa.h5"
if [ -x "$py" ] && "$py" -c 'import h5py, numpy' 2> /dev/null; then
  check summary_matches_series "$py" - "$out" <<'PY'
import json, sys
import h5py, numpy as np
out = sys.argv[1]
s = json.load(open(out + "/summary.json"))
with h5py.File(out + "/fa.h5", "r") as f:
    g = f["forces/wall"]
    t, dt, F = g["time"][:], g["dt"][:], g["force"][:]
    Fx = g["faces/x-/force"][:]
    area = g["faces/x-/contact_area"][:]
    peak_attr = g.attrs["peak_force"]
mag = np.linalg.norm(F, axis=1)
k = int(np.argmax(mag))
w = s["structures"]["wall"]
assert w["peak"]["value"] == mag[k] == peak_attr, (w["peak"], mag[k], peak_attr)
assert w["peak"]["time"] == t[k]
imp = np.zeros(3)
for row, h in zip(F, dt):
    imp = imp + row * h
assert np.allclose(w["impulse"], imp, rtol=1e-12, atol=0), (w["impulse"], imp)
a = s["analysis"]
assert a["structure"] == "wall" and a["face"] == "x-" and a["component"] == "normal"
normal = Fx[:, 0]  # outward normal of x- is -x: F.(-n) = F_x
kk = int(np.argmax(np.abs(normal)))
assert a["peak"]["value"] == normal[kk] and a["peak"]["time"] == t[kk], (a["peak"], normal[kk])
assert abs(a["impulse"] - float(np.sum(normal * dt))) <= 1e-9 * abs(a["impulse"])
assert a["samples"] == len(t)
ref = a["reference"]
assert ref["density"] == 1000 and ref["velocity"] == 1 and ref["width"] == 1 and ref["height"] == 0.1
assert abs(ref["gravity"] - 9.81) < 1e-12
c = a["coefficients"]
f_pk = abs(normal[kk])
assert abs(c["c_pk"] - f_pk / (1000 * 1**2 * 1 * 0.1)) <= 1e-12 * c["c_pk"]  # (7.14)
h_act = area[kk] / 1.0                                                        # (7.15)
f_st = 0.5 * 0.5 * 1000 * 9.81 * h_act**2 * 1.0                               # (7.17)-(7.18)
assert abs(c["f_st_pk"] - f_st) <= 1e-12 * f_st and abs(c["r_pk"] - f_pk / f_st) <= 1e-12 * c["r_pk"]
f_st_hb = 0.5 * 0.5 * 1000 * 9.81 * 0.1**2 * 1.0                              # H_b = 0.1 m
assert abs(c["f_st_hb"] - f_st_hb) <= 1e-12 * f_st_hb and abs(c["r_pk_hb"] - f_pk / f_st_hb) <= 1e-12 * c["r_pk_hb"]
ss = a["steady_state"]
assert ss["status"] in ("found", "none")
if ss["status"] == "none":
    assert ss["value"] is None and c["c_ss"] is None and ss["note"]
print("peak", f_pk, "at", t[kk], "C_pk", c["c_pk"], "R_pk", c["r_pk"], "steady", ss["status"], ss["value"])
PY
else
  echo "skip summary_matches_series: no /usr/bin/python3 with h5py"
fi
# The command line overrides the scene: another structure, a face, references, a window.
expect forces_override_structure 0 '"structure": "domain"' -- "$surge" forces "$out/fa.h5" --json --obstacle domain --face y- --component y
expect forces_override_window 0 '"status": "window"' -- "$surge" forces "$out/fa.h5" --json --window 0.3 0.4
expect forces_override_velocity 0 '"velocity": 2' -- "$surge" forces "$out/fa.h5" --json --velocity 2 --smooth low_pass=50
expect forces_same_structure_keeps_face 0 '"face": "x-",' -- "$surge" forces "$out/fa.h5" --json --obstacle wall
expect forces_structure_drops_face 0 '"face": "",' -- "$surge" forces "$out/fa.h5" --json --obstacle domain
# Errors.
expect forces_missing_file 2 "no such file" -- "$surge" forces "$work/none.h5"
echo "not hdf5" > "$work/text.h5"
expect forces_not_hdf5 2 "is not an HDF5 file" -- "$surge" forces "$work/text.h5"
if [ -x "$py" ] && "$py" -c 'import h5py' 2> /dev/null; then
  "$py" -c "import h5py; h5py.File('$work/foreign.h5', 'w').create_dataset('x', data=[1.0])"
  expect forces_not_surge 2 "is not a Surge result" -- "$surge" forces "$work/foreign.h5"
fi
expect forces_unknown_structure 2 "no structure 'pier'.*structures: domain, wall" -- "$surge" forces "$out/fa.h5" --obstacle pier
expect forces_unknown_face 2 "structure 'wall' has no face 'side' \(faces: x-, x\+, y-, y\+\)" -- "$surge" forces "$out/fa.h5" --face side
expect forces_normal_needs_axis_face 2 "component normal needs an axis face" -- "$surge" forces "$out/fa.h5" --obstacle domain --component normal
expect forces_bad_smooth 2 "unknown filter 'gauss'" -- "$surge" forces "$out/fa.h5" --smooth gauss=1
expect forces_nyquist 2 "Nyquist" -- "$surge" forces "$out/fa.h5" --smooth low_pass=1e6
# Impossible filter settings in the scene: the run still writes summary.json, with a note.
expect run_lenient_summary 0 'completed' -- "$surge" run "$work/fa.yaml" --out "$work/lenient" --progress quiet --set time.end=0.05 --set "analysis.smoothing={low_pass: 1.0e6}"
if grep -q '"notes": "no analysis of .wall.: low_pass cut-off' "$work/lenient/summary.json" 2> /dev/null && grep -q '"wall"' "$work/lenient/summary.json"; then
  echo "ok   run_lenient_summary_json"; pass=$((pass + 1))
else
  echo "FAIL run_lenient_summary_json"; head -20 "$work/lenient/summary.json"; fail=$((fail + 1))
fi
expect forces_scene_error 2 "analysis.structure" -- "$surge" check "$work/fa.yaml" --set analysis.structure=pier
finish "forces cli"

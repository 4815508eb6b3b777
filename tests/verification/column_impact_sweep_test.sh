#!/usr/bin/env bash
# The reduced column-impact sweep in CI (issue 6, "Tests"; ctest label verification): runs
# scenes/sweeps/column_impact_ci.yaml (4 cases of scenes/column_impact_3d.yaml at h = 0.5 m,
# dt <= 2e-3 s, t = 3.5 s, 2 at a time, one thread each) and checks on its sweep.csv the
# seed's findings (Mast 2013 §7.4; spec seed-algorithms.md §5.7) that the issue asks for:
#   1. every case completes and the plateau detector (the scene's analysis section: 0.1 s
#      impulse-preserving average, 2 %, at least 0.5 s) finds a steady state;
#   2. the peak and the steady-state force on the impact face grow with the column width
#      w_c = 2, 3, 5 m (phi = 20 deg): a linear fit has R^2 > 0.95 and a positive slope;
#   3. the steady-state force changes by less than 20 % between phi = 20 and 30 deg at
#      w_c = 3 m ("f_ss is largely independent of phi");
#   4. R_ss = f_ss / f_st within [0.7, 1.5] in every case, with f_st = 1/2 K0 rho0 g H_b^2 w_c
#      (7.17)-(7.19) taken with the surge depth H_b (r_ss_hb). Eq. (7.19) with the grid's contact
#      height H_act (r_ss) gives 0.3-0.4 at h = 0.5 m, because the node-count contact area
#      reaches 4-5 m up a 3 m flow (docs/forces.md, "The grid inflates A_act"); it is printed,
#      not checked.
# Then the plot scripts on the results (a PNG each), and the seed's full 180-case study file:
# `--dry-run` accepts it and `--slurm` writes its job-array script.
#
# Measured 2026-12-02 with the obstacles' gap test and interpolated faces (the defaults since;
# docs/obstacle-faces.md), peak / steady-state force on face x- [kN], steady window, R_pk and
# R_ss with H_b:
#   w_c 2, phi 20: 573.5 / 76.5 over [2.64, 3.5] s, R_pk 7.62, R_ss 1.02
#   w_c 3, phi 20: 833.6 / 109.9 over [2.61, 3.5] s, R_pk 7.38, R_ss 0.97
#   w_c 5, phi 20: 1356.6 / 172.6 over [2.62, 3.5] s, R_pk 7.21, R_ss 0.92
#   w_c 3, phi 30: 244.1 / 117.6 over [2.42, 3.5] s, R_pk 2.16, R_ss 1.04
# fits: peak = 50.9 + 261.1 w_c kN (R^2 1.0000), steady = 13.2 + 31.9 w_c kN (R^2 0.9997);
# f_ss changes +7.0 % from phi 20 to 30.
# Before (node-by-node contact without a gap test; on the 2-core development machine the sweep
# took 58 s alone, 210 s under load 8-9; results the same bit for bit). Peak / steady-state
# force on face x- [kN], steady window, R_pk and R_ss with H_b:
#   w_c 2, phi 20: 142.7 / 66.2 over [1.98, 3.5] s, R_pk 1.89, R_ss 0.88
#   w_c 3, phi 20: 206.5 / 96.3 over [1.54, 3.5] s, R_pk 1.83, R_ss 0.85
#   w_c 5, phi 20: 340.4 / 156.6 over [1.01, 3.5] s, R_pk 1.81, R_ss 0.83
#   w_c 3, phi 30: 111.2 / 88.2 over [2.85, 3.5] s, R_pk 0.98, R_ss 0.78
# fits: peak = 9.7 + 66.1 w_c kN (R^2 0.9999), steady = 5.9 + 30.1 w_c kN (R^2 1.0000);
# f_ss changes 8.4 % from phi 20 to 30. R_ss with H_act (eq. 7.19 literally): 0.24-0.40.
# With the old contact the seed's R_pk 3-9 was not reproduced (1-1.9 with quadratic B-splines;
# 7.1-8.7 with the seed's linear shape functions at w_c 3, phi 20); now 7.2-7.6 at phi 20.
# Why phi = 20 and 30 deg for criterion 3: at phi = 10 and 40 deg the force has not settled by
# 3.5 s (no plateau; w_c = 3 m: 105 kN still falling, 62 kN still rising), so the criterion
# cannot be checked there within this run time (docs/studies/column-impact.md).
# Usage: column_impact_sweep_test.sh <surge binary> <source dir>
set -u
surge=$1
src=$2
py=/usr/bin/python3
. "$(dirname "$0")/../support/cli_checks.sh"
cd "$work" || exit 1

# The seed's full study: 180 valid cases, and a Slurm array over them.
full=$src/scenes/sweeps/column_impact_full.yaml
out=$("$surge" sweep "$full" --out "$work/full" --dry-run 2>&1)
rc=$?
if [ "$rc" -eq 0 ] && grep -q 'all 180 cases valid' <<<"$out" \
   && grep -q "case_179_wc=6_H=4.0_phi=40 \[not_run\] .*parameters.dx=0.25" <<<"$out"; then
  ok full_dry_run
else
  bad "full_dry_run: exit $rc"; echo "$out" | tail -5
fi
out=$("$surge" sweep "$full" --out "$work/full" --slurm "$work/job.sh" 2>&1)
rc=$?
if [ "$rc" -eq 0 ] && grep -q '^#SBATCH --array=0-179' "$work/job.sh" \
   && grep -q '^#SBATCH --cpus-per-task=4' "$work/job.sh" && grep -q -- '--case' "$work/job.sh"; then
  ok full_slurm_script
else
  bad "full_slurm_script: exit $rc"; echo "$out" | tail -5; head -20 "$work/job.sh" 2>/dev/null
fi

# The reduced sweep.
ci=$src/scenes/sweeps/column_impact_ci.yaml
start=$(date +%s)
out=$("$surge" sweep "$ci" --out "$work/ci" --jobs 2 2>&1)
rc=$?
echo "sweep: $(( $(date +%s) - start )) s wall"
if [ "$rc" -eq 0 ] && grep -q '4 cases: 4 completed' <<<"$out"; then
  ok ci_sweep_runs
else
  bad "ci_sweep_runs: exit $rc"; echo "$out" | tail -12
fi

csv=$work/ci/sweep.csv
if [ -s "$csv" ]; then
  if "$py" - "$csv" <<'PY'; then ok ci_sweep_criteria; else bad ci_sweep_criteria; fi
import csv, sys
rows = {r["case"].split("_", 2)[2]: r for r in csv.DictReader(open(sys.argv[1]))}
failed = []
def check(name, cond, detail):
    print(("ok   " if cond else "FAIL ") + name + ": " + detail)
    if not cond:
        failed.append(name)
def num(r, key):
    v = r.get(key, "")
    return float(v) if v not in ("", None) else None
for name, r in rows.items():
    print(f"  {name}: wall {r['wall_s']} s, peak {abs(num(r, 'analysis.peak.value')) / 1e3:.1f} kN at "
          f"{num(r, 'analysis.peak.time'):.3f} s, steady {r['analysis.steady_state.status']} "
          f"{(num(r, 'analysis.steady_state.value') or 0) / 1e3:.1f} kN over "
          f"[{num(r, 'analysis.steady_state.t0'):.2f}, {num(r, 'analysis.steady_state.t1'):.2f}] s, "
          f"R_pk,Hb {num(r, 'analysis.coefficients.r_pk_hb')}, R_ss,Hb {num(r, 'analysis.coefficients.r_ss_hb')}, "
          f"R_ss (H_act) {num(r, 'analysis.coefficients.r_ss')}, C_pk {num(r, 'analysis.coefficients.c_pk')}, "
          f"C_ss {num(r, 'analysis.coefficients.c_ss')}")
    check(f"{name}_completed", r["status"] == "completed", r["status"])
    check(f"{name}_steady_state", r["analysis.steady_state.status"] == "found",
          r["analysis.steady_state.status"] + " " + r.get("analysis.steady_state.note", ""))
    check(f"{name}_face", r["analysis.face"] == "x-" and r["analysis.component"] == "normal",
          r["analysis.face"] + " " + r["analysis.component"])
if failed:
    sys.exit(1)

def fit(xs, ys):
    """Least-squares line y = a + b x and its R^2."""
    n = len(xs)
    mx, my = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mx) ** 2 for x in xs)
    b = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    a = my - b * mx
    ss_res = sum((y - a - b * x) ** 2 for x, y in zip(xs, ys))
    ss_tot = sum((y - my) ** 2 for y in ys)
    return a, b, 1 - ss_res / ss_tot

widths = ["wc2_phi20", "wc3_phi20", "wc5_phi20"]
wc = [num(rows[c], "parameters.wc") for c in widths]
for what, key in (("peak", "analysis.peak.value"), ("steady", "analysis.steady_state.value")):
    f = [abs(num(rows[c], key)) for c in widths]
    a, b, r2 = fit(wc, f)
    check(f"{what}_linear_in_width", r2 > 0.95 and b > 0,
          f"f = {a / 1e3:.1f} + {b / 1e3:.1f} w_c kN, R^2 = {r2:.4f} (need > 0.95, slope > 0)")
f20 = num(rows["wc3_phi20"], "analysis.steady_state.value")
f30 = num(rows["wc3_phi30"], "analysis.steady_state.value")
change = abs(f30 - f20) / f20
check("steady_independent_of_phi", change < 0.2,
      f"f_ss {f20 / 1e3:.1f} kN (phi 20) vs {f30 / 1e3:.1f} kN (phi 30): {100 * change:.1f} % (need < 20 %)")
for name, r in rows.items():
    rss = num(r, "analysis.coefficients.r_ss_hb")
    check(f"{name}_r_ss", rss is not None and 0.7 <= rss <= 1.5, f"R_ss,Hb = {rss} (need 0.7-1.5)")
sys.exit(1 if failed else 0)
PY
else
  bad "ci_sweep_criteria: no $csv"
fi

# The plot scripts on the sweep's results.
if "$py" "$src/scripts/plot_sweep.py" "$csv" --x parameters.wc --y parameters.phi --out "$work/sweep.png" >/dev/null \
   && [ -s "$work/sweep.png" ]; then ok plot_sweep; else bad plot_sweep; fi
if "$py" "$src/scripts/plot_sweep.py" "$csv" --histories --out "$work/histories.png" >/dev/null \
   && [ -s "$work/histories.png" ]; then ok plot_sweep_histories; else bad plot_sweep_histories; fi
case3=$(ls -d "$work"/ci/case_001_wc3_phi20 2>/dev/null)
if "$py" "$src/scripts/plot_forces.py" "$case3/column_impact_3d.h5" --analysis --out "$work/analysis.png" >/dev/null \
   && [ -s "$work/analysis.png" ]; then ok plot_forces_analysis; else bad plot_forces_analysis; fi

finish

#!/usr/bin/env bash
# The plot scripts (scripts/plot_forces.py, scripts/plot_sweep.py, scripts/antilocking_report.py)
# on small data (ctest label
# unit): the 2 x 2 tiny sweep of tests/data/sweeps/tiny_product.yaml (a 2-D block towards a
# post, well under a second a case) gives a sweep.csv, results and summary.json files; each
# plot mode must write a non-empty PNG, and a bad column must fail with a message naming it.
# Usage: plot_scripts_test.sh <surge binary> <source dir>
set -u
surge=$1
src=$2
py=/usr/bin/python3
. "$(dirname "$0")/../../support/cli_checks.sh"
cd "$work" || exit 1

png() {  # png <name> <file> -- command...: the command exits 0 and writes a PNG
  local name=$1 file=$2
  shift 3
  local out
  if ! out=$("$@" 2>&1); then bad "$name: exit status $?"; echo "$out" | tail -5; return; fi
  if [ -s "$file" ] && [ "$(head -c 8 "$file" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ]; then
    ok "$name"
  else
    bad "$name: no PNG at $file"; echo "$out" | tail -5
  fi
}

if ! "$surge" sweep "$src/tests/data/sweeps/tiny_product.yaml" --out "$work/tiny" --jobs 2 >/dev/null 2>&1; then
  bad "tiny sweep did not run"; echo "0 passed, 1 failed"; exit 1
fi
h5=$work/tiny/case_003_w=0.2_v=1/sweep_tiny_2d.h5
png plot_forces "$work/f.png" -- "$py" "$src/scripts/plot_forces.py" "$h5" --faces --out "$work/f.png"
png plot_forces_analysis "$work/a.png" -- "$py" "$src/scripts/plot_forces.py" "$h5" --analysis --out "$work/a.png"
png plot_forces_analysis_default_name "${h5%.h5}_analysis.png" -- "$py" "$src/scripts/plot_forces.py" "$h5" --analysis
png plot_sweep "$work/s.png" -- "$py" "$src/scripts/plot_sweep.py" "$work/tiny/sweep.csv" --x w --y v --out "$work/s.png"
png plot_sweep_default_name "$work/tiny/sweep.png" -- "$py" "$src/scripts/plot_sweep.py" "$work/tiny/sweep.csv" --x v --y w --quantities f_pk analysis.impulse
png plot_sweep_histories "$work/h.png" -- "$py" "$src/scripts/plot_sweep.py" "$work/tiny/sweep.csv" --histories --match "w=0.2" --out "$work/h.png"

# The anti-locking comparison (scripts/antilocking_report.py) on a coarse, short dam break with
# barrier: fourteen runs (scripts/antilocking_report.py OPTIONS), a CSV row each, both PNGs.
png antilocking_report "$work/al/plots/antilocking_barrier_pressure.png" -- "$py" "$src/scripts/antilocking_report.py" \
  --surge "$surge" --out "$work/al" --plots "$work/al/plots" --end 0.6 --set grid.cell_size=0.5 \
  --set bodies.0.particles_per_cell=2
if [ -s "$work/al/plots/antilocking_barrier_force.png" ] && [ "$(wc -l < "$work/al/antilocking_report.csv")" = 15 ]; then
  ok antilocking_report_table
else
  bad "antilocking_report_table: $(cat "$work/al/antilocking_report.csv" 2>&1 | head -3)"
fi

out=$("$py" "$src/scripts/plot_sweep.py" "$work/tiny/sweep.csv" --x width --y v 2>&1)
if [ $? -ne 0 ] && grep -q "no column 'width'" <<<"$out"; then ok plot_sweep_bad_column; else bad "plot_sweep_bad_column: $out"; fi
out=$("$py" "$src/scripts/plot_forces.py" "$h5" --analysis "$work/none.json" 2>&1)
if [ $? -ne 0 ] && grep -q "none.json: no such file" <<<"$out"; then ok plot_forces_no_summary; else bad "plot_forces_no_summary: $out"; fi

finish

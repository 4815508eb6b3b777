#!/usr/bin/env bash
# scripts/convergence in CI (issue 8 item 1, "CI runs a tiny ladder"; ctest label verification):
#  1. the elastic bar's first-mode period (scenes/studies/elastic_bar.yaml) with linear shape
#     functions and FLIP on its 3 coarsest cell sizes (1, 0.5, 0.25 m): the error against the
#     closed form 10 s must fall at every refinement (--check-falls);
#  2. the report: --doc writes the table and the observed order, --plots the PNG;
#  3. bad study files exit 2 with the file, line, column and key of the mistake.
# Measured on the 2-core development machine (load 4): 3 runs, about 25 s in all.
# Usage: convergence_test.sh <surge binary> <source dir>
set -u
surge=$1
src=$2
py=/usr/bin/python3
conv=$src/scripts/convergence
. "$(dirname "$0")/../support/cli_checks.sh"
cd "$work" || exit 1

out=$("$py" "$conv" "$src/scenes/studies/elastic_bar.yaml" --surge "$surge" --out "$work/studies" \
      --only linear:flip --levels 3 --check-falls --doc "$work/accuracy.md" --plots "$work/plots" 2>&1)
rc=$?
echo "$out"
if [ "$rc" -eq 0 ] && grep -q 'check elastic_bar linear flip: .*: falls' <<<"$out"; then
  ok error_falls_with_cell_size
else
  bad "error_falls_with_cell_size: exit $rc"
fi
if grep -q '^| linear | FLIP | 0.25 | 2 | 800 |' "$work/accuracy.md" 2>/dev/null \
   && grep -q 'Observed order' "$work/accuracy.md" && [ -s "$work/plots/accuracy_elastic_bar.png" ] \
   && [ "$(wc -l < "$work/studies/elastic_bar/study.csv")" -eq 4 ]; then
  ok report_table_csv_and_plot
else
  bad report_table_csv_and_plot; cat "$work/accuracy.md" 2>/dev/null | head -30
fi
# A rerun reuses the recorded runs (run.json with the same command line): no surge needed.
expect resume_without_rerunning 0 'check elastic_bar linear flip: .*: falls' -- \
  "$py" "$conv" "$src/scenes/studies/elastic_bar.yaml" --surge /nonexistent/surge-but-executable-check-skipped \
  --out "$work/studies" --only linear:flip --levels 3 --check-falls

# Bad study files: file:line:column: key: reason, exit 2.
study() { sed "s#SCENE#$src/scenes/elastic_bar_1d.yaml#" > "$work/$1.yaml"; }
base='name: bad
scene: SCENE
ladder: {cell_size: [1.0, 0.5], particles_per_cell: 2}
measure: {quantity: period, signal: {force: {structure: domain, face: x-, component: x}}}
reference: {value: 10}'
study unknown_key <<<"$base
shapes: [linear]"
expect unknown_key 2 'unknown_key.yaml:6:1: shapes: unknown key' -- "$py" "$conv" "$work/unknown_key.yaml" --dry-run
study bad_shape <<<"$base
shape_functions: [linear, quadratic]"
expect bad_shape 2 'bad_shape.yaml:6:27: shape_functions\[1\]: expected one of linear, gimp, quadratic_bspline, cubic_bspline, got "quadratic"' -- \
  "$py" "$conv" "$work/bad_shape.yaml" --dry-run
study not_refining <<<"${base/\[1.0, 0.5\]/[0.5, 1.0]}"
expect not_refining 2 'not_refining.yaml:3:21: ladder.cell_size: expected cell sizes from coarse to fine' -- \
  "$py" "$conv" "$work/not_refining.yaml" --dry-run
study bad_number <<<"${base/value: 10/value: ten}"
expect bad_number 2 'bad_number.yaml:5:20: reference.value: expected a number, got "ten"' -- \
  "$py" "$conv" "$work/bad_number.yaml" --dry-run
study no_measure <<<"${base/measure:/measured:}"
expect no_measure 2 'no_measure.yaml:4:1: measured: unknown key' -- "$py" "$conv" "$work/no_measure.yaml" --dry-run
study syntax <<<"$base
transfers: [flip"
expect yaml_syntax 2 'syntax.yaml:[0-9]+:[0-9]+: YAML syntax' -- "$py" "$conv" "$work/syntax.yaml" --dry-run
study bad_shape_expr <<<"${base/signal: \{force: \{structure: domain, face: x-, component: x\}\}/signal: {modal: {field: velocity, component: x, shape: \"sin(pi * W)\"\}\}}"
expect bad_mode_shape 2 "bad_shape_expr.yaml:4:.*measure.signal.modal.shape: cannot evaluate the mode shape: name 'W' is not defined" -- \
  "$py" "$conv" "$work/bad_shape_expr.yaml" --dry-run
finish convergence_test

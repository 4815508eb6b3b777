#!/usr/bin/env bash
# End-to-end checks of `surge sweep` (ctest label unit): dry run, validation errors naming the
# case and the override, a 2 x 2 product run with --jobs 2 and its sweep.csv, resume (nothing
# rerun), an interrupted case continued from its checkpoint, --case / --collect, the Slurm
# script, and a failing case beside good ones.
# Usage: sweep_cli_test.sh <surge binary> <source dir>
set -u
surge=$1
src=$2
. "$(dirname "$0")/../../support/cli_checks.sh"
cd "$work" || exit 1

tiny=$src/tests/data/sweeps/tiny_product.yaml
out=$work/tiny
expect dry_run 0 'case_003_w=0.2_v=1 \[not_run\] .*--set .parameters.v=1.' -- "$surge" sweep "$tiny" --out "$out" --dry-run
[ ! -e "$out/case_000_w=0.1_v=0.5" ] && ok dry_run_runs_nothing || bad "dry_run_runs_nothing: a case folder exists"

# A bad value or key path fails validation before anything runs: the message names the sweep
# file's line, the case and the override.
cat > "$work/bad_path.yaml" <<YAML
base: $src/tests/data/scenes/sweep_tiny_2d.yaml
parameters:
  v: [1, 2]
  bodies.3.velocity: [[1, 0]]
YAML
expect bad_override_path 2 'bad_path.yaml:4:23: case case_000_v=1_velocity=1_0: --set bodies.3.velocity=\[1, 0\]: bodies\[3\]: list index 3 out of range' -- "$surge" sweep "$work/bad_path.yaml" --out "$work/bad"
cat > "$work/bad_value.yaml" <<YAML
base: $src/tests/data/scenes/sweep_tiny_2d.yaml
parameters:
  materials.m.bulk_modulus: [1.0e5, -3]
YAML
expect bad_override_value 2 'bad_value.yaml:3:37: case case_001_bulk_modulus=-3: .*materials\.m\.bulk_modulus' -- "$surge" sweep "$work/bad_value.yaml" --out "$work/bad"
[ ! -e "$work/bad" ] && ok bad_runs_nothing || bad "bad_runs_nothing: $work/bad exists"
expect bad_sweep_key 2 'k.yaml:2:1: jbos: unknown key' -- bash -c "printf 'base: a.yaml\njbos: 2\n' > k.yaml && '$surge' sweep k.yaml"

# 2 x 2 product, 2 at a time.
expect run_2x2 0 'sweep: 4 cases: 4 completed' -- "$surge" sweep "$tiny" --out "$out" --jobs 2
csv=$out/sweep.csv
if [ -s "$csv" ] && [ "$(wc -l <"$csv")" -eq 5 ] && head -1 "$csv" | grep -q '^case,w,v,status,exit_code,wall_s,detail' \
   && [ "$(cut -d, -f1-4 "$csv" | tail -4 | tr '\n' ' ')" = "case_000_w=0.1_v=0.5,0.1,0.5,completed case_001_w=0.1_v=1,0.1,1,completed case_002_w=0.2_v=0.5,0.2,0.5,completed case_003_w=0.2_v=1,0.2,1,completed " ]; then
  ok sweep_csv_rows
else
  bad "sweep_csv_rows: unexpected $csv"; cat "$csv"
fi
[ -s "$out/case_002_w=0.2_v=0.5/sweep_tiny_2d.h5" ] && grep -q 'finished\|steps' "$out/case_002_w=0.2_v=0.5/log.txt" \
  && ok case_results_and_log || bad "case_results_and_log: no .h5 or log.txt of case 2"

# surge run writes summary.json; its leaves follow as dotted columns, the same in every row.
if [ -s "$out/case_000_w=0.1_v=0.5/summary.json" ]; then
  if /usr/bin/python3 - "$csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
extra = rows[0][7:]
assert extra and all(c and " " not in c for c in extra), extra[:5]
assert any("." in c for c in extra), extra[:5]
assert all(len(r) == len(rows[0]) for r in rows), [len(r) for r in rows]
assert all(any(cell for cell in r[7:]) for r in rows[1:])
PY
  then
    ok csv_summary_columns
  else
    bad "csv_summary_columns: $(head -1 "$csv" | cut -c1-300)"
  fi
fi

# Another sweep into the same folder while one runs is refused.
exec 9>"$out/sweep.lock"
if flock -n 9; then
  expect lock_refused 1 'another surge sweep' -- "$surge" sweep "$tiny" --out "$out"
  flock -u 9
fi
exec 9>&-

# A sweep killed hard (SIGKILL) leaves its cases running; they hold the lock until they end.
# The case must outlive the kill and the next sweep's start: 8 s of two_disks take about 1.2 s
# (1.5 s took 0.2 s and sometimes ended first, so the check raced).
cat > "$work/slow.yaml" <<YAML
base: $src/scenes/two_disks_2d.yaml
parameters:
  time.end: [8]
YAML
"$surge" sweep "$work/slow.yaml" --out "$work/slow" >/dev/null 2>&1 &
spid=$!
for _ in $(seq 50); do [ -s "$work/slow/case_000_end=8/log.txt" ] && break; sleep 0.1; done
kill -9 "$spid"; wait "$spid" 2>/dev/null
expect lock_orphans 1 'cases left running by one that was killed' -- "$surge" sweep "$work/slow.yaml" --out "$work/slow"
# Wait for the orphaned case to end (about 1 s in Release; several times that under sanitizers).
for _ in $(seq 1200); do pgrep -f "run $src/scenes/two_disks_2d.yaml --out $work/slow" >/dev/null || break; sleep 0.1; done
expect lock_released 0 '1 cases, 0 to run \(1 completed before\)' -- "$surge" sweep "$work/slow.yaml" --out "$work/slow"

# A sweep stopped with Ctrl-C (SIGINT to the sweep): its case writes a checkpoint and ends
# interrupted; the next sweep continues it from that checkpoint (surge run --restart) instead of
# starting over, and the result equals an uninterrupted run bit for bit.
cat > "$work/long.yaml" <<YAML
base: $src/scenes/two_disks_2d.yaml
parameters:
  time.end: [4]
set: {output.checkpoint_every: 0.2, output.every: 0.5}
YAML
"$surge" sweep "$work/long.yaml" --out "$work/long" >"$work/long_first.log" 2>&1 &
spid=$!
case_dir=$work/long/case_000_end=4
for _ in $(seq 100); do ls "$case_dir"/checkpoints/*_step_*.h5 >/dev/null 2>&1 && break; sleep 0.05; done
kill -INT "$spid"; wait "$spid"; code=$?
if [ "$code" -eq 130 ] && grep -q 'case_000_end=4: interrupted' "$work/long_first.log"; then ok resume_interrupted
else bad "resume_interrupted: exit $code"; cat "$work/long_first.log"; fi
expect resume_continues 0 'case_000_end=4: continuing from .*/checkpoints/two_disks_2d_step_[0-9]+\.h5' -- "$surge" sweep "$work/long.yaml" --out "$work/long"
grep -q 'completed' "$work/long/sweep.csv" && ok resume_completed || bad "resume_completed: $(cat "$work/long/sweep.csv")"
"$surge" run "$src/scenes/two_disks_2d.yaml" --out "$work/long_ref" --progress quiet --set time.end=4 \
  --set output.checkpoint_every=0.2 --set output.every=0.5 >/dev/null 2>&1
expect resume_bitwise 0 'numeric datasets' -- /usr/bin/python3 "$src/tests/regression/compare_results.py" "$work/long_ref" "$case_dir" two_disks_2d --ignore-attr @threads
# --force starts it over.
expect force_starts_over 0 '1 cases, 1 to run' -- "$surge" sweep "$work/long.yaml" --out "$work/long" --force
grep -q 'continuing from' "$work/long/case_000_end=4/log.txt" && bad "force_starts_over_log: the log says it continued" || ok force_starts_over_log

# Rerun: every case is completed, nothing runs again (logs untouched).
before=$(stat -c %Y.%N "$out"/case_*/log.txt "$out"/case_*/*.h5 | md5sum)
sleep 1
expect rerun_skips 0 '4 cases, 0 to run \(4 completed before\)' -- "$surge" sweep "$tiny" --out "$out" --jobs 2
after=$(stat -c %Y.%N "$out"/case_*/log.txt "$out"/case_*/*.h5 | md5sum)
[ "$before" = "$after" ] && ok rerun_untouched || bad "rerun_untouched: a case ran again"
expect dry_run_shows_skip 0 'case_001_w=0.1_v=1 \[completed: skipped\]' -- "$surge" sweep "$tiny" --out "$out" --dry-run

# One case as a Slurm array task would run it, then the table.
rm -rf "$out/case_001_w=0.1_v=1" "$csv"
expect case_one 0 '\[1/1\] case_001_w=0.1_v=1: completed' -- "$surge" sweep "$tiny" --out "$out" --case 1
expect case_one_again 0 'already completed' -- "$surge" sweep "$tiny" --out "$out" --case 1
expect case_out_of_range 2 '--case 4: the sweep has 4 cases' -- "$surge" sweep "$tiny" --out "$out" --case 4
expect collect 0 'sweep: 4 cases: 4 completed' -- "$surge" sweep "$tiny" --out "$out" --collect
[ "$(grep -c ',completed,0,' "$csv")" -eq 4 ] && ok collect_csv || { bad "collect_csv"; cat "$csv"; }

# Slurm job-array script.
expect slurm 0 'array=0-3' -- "$surge" sweep "$tiny" --out "$out" --slurm "$work/job.sh"
if grep -q '^#SBATCH --array=0-3$' "$work/job.sh" && grep -q -- 'sweep .*tiny_product.yaml. --case "$SLURM_ARRAY_TASK_ID"' "$work/job.sh" \
   && grep -q -- '--collect' "$work/job.sh" && bash -n "$work/job.sh"; then
  ok slurm_script
else
  bad "slurm_script"; cat "$work/job.sh"
fi

# A case that fails at run time (the block leaves the open domain side: health check, exit 3)
# beside two good ones: the others finish, the exit code is non-zero, the table says which.
cat > "$work/mixed.yaml" <<YAML
base: $src/tests/data/scenes/sweep_tiny_2d.yaml
parameters:
  v: [0.5, 1.0e4, 1]
set: {time.end: 0.005}
YAML
expect failing_case 1 'sweep: 3 cases: 2 completed, 1 unhealthy' -- "$surge" sweep "$work/mixed.yaml" --out "$work/mixed" --jobs 2
if grep -q '^case_001_v=1.0e4,1.0e4,unhealthy,3,' "$work/mixed/sweep.csv" && [ "$(grep -c ',completed,0,' "$work/mixed/sweep.csv")" -eq 2 ]; then
  ok failing_case_csv
else
  bad "failing_case_csv"; cat "$work/mixed/sweep.csv"
fi
# Resume reruns only the failed case.
expect failing_case_rerun 1 '3 cases, 1 to run \(2 completed before\)' -- "$surge" sweep "$work/mixed.yaml" --out "$work/mixed"

# Changing the sweep-wide overrides makes completed cases outdated: they run again.
sed -i 's/time.end: 0.005/time.end: 0.004/' "$work/mixed.yaml"
expect outdated_rerun 1 '3 cases, 3 to run \(0 completed before\)' -- "$surge" sweep "$work/mixed.yaml" --out "$work/mixed" --jobs 3

# A case is outdated when its resolved scene changed, not when only a comment did.
cp "$src/tests/data/scenes/sweep_tiny_2d.yaml" "$work/own.yaml"
printf 'base: own.yaml\nparameters: {v: [1]}\nset: {time.end: 0.004}\n' > "$work/own_sweep.yaml"
expect own_first 0 '1 cases, 1 to run' -- "$surge" sweep "$work/own_sweep.yaml" --out "$work/own"
echo "# a comment" >> "$work/own.yaml"
expect own_comment 0 '1 cases, 0 to run \(1 completed before\)' -- "$surge" sweep "$work/own_sweep.yaml" --out "$work/own"
sed -i 's/density: 1000/density: 1100/' "$work/own.yaml"
expect own_changed 0 'case_000_v=1 \[outdated\]' -- "$surge" sweep "$work/own_sweep.yaml" --out "$work/own" --dry-run

finish

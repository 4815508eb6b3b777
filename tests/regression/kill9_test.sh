#!/usr/bin/env bash
# Crash safety under kill -9 (issue 9, item 2; ctest label regression). The small 2-D dam break
# against a barrier (tests/data/scenes/dam_barrier_small_2d.yaml, run to 0.6 s with a checkpoint
# every 0.02 s) runs once uninterrupted. A second run is then killed with SIGKILL after a random
# delay (0.05-0.85 s, from a seeded generator, each logged), at least 6 times in a row; after
# each kill
#   - every file is checked (check_killed_files.py): every checkpoint under its final name opens
#     and reads whole (a checkpoint being written is only a .tmp), the result .h5 opens, every
#     snapshot the .xmf lists reads with the listed dimensions, every series reads;
#   - the run is continued with --restart from the newest checkpoint, or from scratch with
#     --force when the kill came before the first checkpoint.
# A run that finishes before its kill is not counted; the chain then starts again from scratch.
# After the last kill the run is continued to the end and must equal the uninterrupted result
# bit for bit (compare_results.py: every numeric dataset, the force summaries, CSVs, .xmf,
# summary.json).
# Usage: kill9_test.sh <surge binary> <source dir> [seed]; the seed defaults to 9 (KILL9_SEED in
# the environment overrides it). Measured: about 15 s on 2 cores.
set -u
surge=$1
src=$2
seed=${KILL9_SEED:-${3:-9}}
. "$src/tests/support/cli_checks.sh"
compare="/usr/bin/python3 $src/tests/regression/compare_results.py"
check="/usr/bin/python3 $src/tests/regression/check_killed_files.py"
kills_wanted=6

sed 's/^time: {end: 0.3,/time: {end: 0.6,/; s/checkpoint_every: 0.04}/checkpoint_every: 0.02}/' \
  "$src/tests/data/scenes/dam_barrier_small_2d.yaml" > "$work/dam.yaml"
grep -q 'end: 0.6' "$work/dam.yaml" && grep -q 'checkpoint_every: 0.02' "$work/dam.yaml" \
  || { bad "scene_edit: the shared scene changed; update the sed in kill9_test.sh"; finish kill9; exit; }
run=("$surge" run "$work/dam.yaml" --threads 2 --progress quiet)

start=$(date +%s.%N)
expect full_run 0 'completed' -- "${run[@]}" --out "$work/full"
echo "uninterrupted run: $(echo "$(date +%s.%N) - $start" | bc) s"

RANDOM=$seed  # bash's generator: the same delays for the same seed
echo "seed $seed"
kills=0
attempt=0
restarts=0
fresh=0
files_ok=1
mode=fresh
while [ "$kills" -lt "$kills_wanted" ] && [ "$attempt" -lt 40 ]; do
  attempt=$((attempt + 1))
  delay=$(printf '0.%03d' $((50 + RANDOM % 800)))
  if [ "$mode" = fresh ]; then
    cmd=("${run[@]}" --out "$work/part" --force)
    from="scratch"
  else
    newest=$(ls "$work"/part/checkpoints/dam_barrier_step_*.h5 | tail -1)
    cmd=("${run[@]}" --restart "$newest")
    from=${newest##*/}
  fi
  "${cmd[@]}" > "$work/log_$attempt.txt" 2>&1 &
  pid=$!
  sleep "$delay"
  if kill -9 "$pid" 2> /dev/null; then
    wait "$pid" 2> /dev/null
    kills=$((kills + 1))
    summary=$($check "$work/part" dam_barrier)
    rc=$?
    echo "kill $kills (attempt $attempt): from $from, SIGKILL after $delay s; $summary"
    if [ "$rc" -ne 0 ]; then files_ok=0; fi
  else
    wait "$pid"
    rc=$?
    echo "attempt $attempt: from $from, finished (exit $rc) before its kill at $delay s; starting again from scratch"
    if [ "$rc" -ne 0 ]; then bad "run_exit: attempt $attempt exited $rc"; tail -5 "$work/log_$attempt.txt"; fi
    mode=fresh
    continue
  fi
  if ls "$work"/part/checkpoints/dam_barrier_step_*.h5 > /dev/null 2>&1; then
    mode=restart
    restarts=$((restarts + 1))
  else
    mode=fresh
    fresh=$((fresh + 1))
  fi
done
if [ "$kills" -ge "$kills_wanted" ]; then ok "killed $kills times ($restarts continued from a checkpoint, $fresh from scratch)"
else bad "kills: only $kills of $kills_wanted in $attempt attempts"; fi
if [ "$files_ok" -eq 1 ]; then ok "files_whole_after_every_kill"; else bad "files_whole_after_every_kill"; fi

if [ "$mode" = fresh ]; then
  expect final_run 0 'completed' -- "${run[@]}" --out "$work/part" --force
else
  newest=$(ls "$work"/part/checkpoints/dam_barrier_step_*.h5 | tail -1)
  echo "final: continuing from ${newest##*/}"
  expect final_restart 0 'completed' -- "${run[@]}" --restart "$newest"
fi
if ls "$work"/part/checkpoints/*.tmp > /dev/null 2>&1; then
  echo "note: $(ls "$work"/part/checkpoints/*.tmp | wc -l) stale .tmp checkpoint(s) left by kills"
fi
expect bitwise_after_kills 0 'numeric datasets' -- $compare "$work/full" "$work/part" dam_barrier
finish kill9

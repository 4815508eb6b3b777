#!/usr/bin/env bash
# Checkpoint and restart (issue 9, item 3; ctest label regression), and the result-folder
# safety of item 5 (--force, scene names).
#   1. A coarse 2-D dam break against a barrier (600 particles, ~800 steps, force log on the
#      barrier and the domain walls, checkpoints every 0.04 s, the last 3 kept) runs
#      uninterrupted; a second run stops after step 450 as on Ctrl-C (hidden --stop-at-step:
#      checkpoint, flush, exit 130) and is restarted from its OLDEST kept checkpoint, so the
#      rows and the snapshot written after that checkpoint must be cut away. The restarted
#      result must equal the uninterrupted one bit for bit: every numeric dataset of the .h5
#      (snapshots, energy, forces), the force summary attributes, the CSVs, the .xmf and
#      summary.json (compare_results.py).
#      The same scene with artificial bulk viscosity (q_p carried between steps), restarted on
#      one thread: bit for bit too.
#   2. A dynamic Bullet box falling through the air (3-D, 1600 particles) restarted from a
#      checkpoint before it lands: bit for bit as well (Bullet's own body state is in the
#      checkpoint). The same box resting on the floor (a Bullet contact with the floor slab)
#      restarted during that contact: bit for bit too (Bullet's contact manifolds, with their
#      warm-start impulses, are in the checkpoint and contacts are solved in body order).
#   3. Refusals (exit 2): a rerun into an existing result without --force (the message names the
#      file and offers --force and --restart), a checkpoint restarted with another scene (both
#      files named) or other --set overrides or a changed mesh file (named), a file that is not a
#      checkpoint, a scene name with a path in it; the existing-result refusal comes before the
#      scene is built. --force replaces the result and clears the old run's checkpoints.
# Usage: restart_test.sh <surge binary> <source dir>. Measured: 15.5 s in the full ctest run (2 cores).
set -u
surge=$1
src=$2
. "$src/tests/support/cli_checks.sh"
compare="/usr/bin/python3 $src/tests/regression/compare_results.py"

cp "$src/tests/data/scenes/dam_barrier_small_2d.yaml" "$work/dam.yaml"

# 1. Dam break: uninterrupted, stopped, restarted from the oldest kept checkpoint.
expect dam_full 0 'completed' -- "$surge" run "$work/dam.yaml" --out "$work/full" --progress quiet
expect dam_stopped 130 'interrupted at t' -- "$surge" run "$work/dam.yaml" --out "$work/part" --progress quiet --stop-at-step 450
ckpts=("$work"/part/checkpoints/dam_barrier_step_*.h5)
if [ "${#ckpts[@]}" -eq 3 ] && [ -f "$work/part/checkpoints/dam_barrier_step_000000450.h5" ] \
  && ! ls "$work"/part/checkpoints/*.tmp > /dev/null 2>&1; then
  ok "dam_checkpoints_kept"
else
  bad "dam_checkpoints_kept: expected the newest 3 (the last at step 450): ${ckpts[*]##*/}"
fi
oldest=${ckpts[0]}
# A half-written checkpoint a kill -9 can leave behind: the restart must clear it (listing below).
printf 'partial' > "$work/part/checkpoints/dam_barrier_step_000000999.h5.tmp"
expect dam_restart 0 'continuing from .* step [0-9]+' -- "$surge" run "$work/dam.yaml" --restart "$oldest" --progress quiet
expect dam_bitwise 0 'numeric datasets' -- $compare "$work/full" "$work/part" dam_barrier
# The restarted run wrote its own checkpoints again; the newest is the full run's newest; the stale
# .tmp is gone.
if cmp -s <(ls "$work/full/checkpoints") <(ls "$work/part/checkpoints"); then ok "dam_checkpoints_after_restart"
else bad "dam_checkpoints_after_restart: $(ls "$work/part/checkpoints" | tr '\n' ' ')"; fi

# 1b. The same with artificial bulk viscosity: its q_p is handed from one step to the next in
# the Workspace, and the checkpoint carries it (without it the restart differs from its first
# step on).
sed 's/viscosity: 0.001}/viscosity: 0.001, bulk_viscosity: {}}/; s/^name: dam_barrier/name: dam_bv/' "$work/dam.yaml" > "$work/dam_bv.yaml"
expect bv_full 0 'completed' -- "$surge" run "$work/dam_bv.yaml" --out "$work/bv_full" --progress quiet
expect bv_stopped 130 'interrupted' -- "$surge" run "$work/dam_bv.yaml" --out "$work/bv_part" --progress quiet --stop-at-step 450
bv_oldest=$(ls "$work"/bv_part/checkpoints/dam_bv_step_*.h5 | head -1)
expect bv_restart 0 'completed' -- "$surge" run "$work/dam_bv.yaml" --restart "$bv_oldest" --progress quiet --threads 1
expect bv_bitwise 0 'numeric datasets' -- $compare "$work/bv_full" "$work/bv_part" dam_bv

# 2. A dynamic Bullet body: in flight and resting on the floor, both bit for bit.
cat > "$work/box.yaml" <<'YAML'
name: box_push
dimension: 3
time: {end: 0.3}
gravity: [0, -9.81, 0]
grid: {cell_size: 0.05}
domain: {min: [0, 0, 0], max: [1.2, 0.6, 0.25], walls: {x-: slip, x+: slip, y-: slip, z-: slip, z+: slip}}
materials:
  water: {model: newtonian_fluid, density: 1000, bulk_modulus: 2.0e5, viscosity: 0.001}
bodies:
  - {name: column, material: water, region: {box: {min: [0, 0, 0], max: [0.25, 0.4, 0.25]}}, particles_per_cell: 2}
obstacles:
  - name: box
    shape: {box: {min: [0.6, 0.2, 0.05], max: [0.75, 0.35, 0.2]}}
    motion: {dynamic: {density: 500}}
output: {every: 0.1, checkpoint_every: 0.05, checkpoints_keep: 10}
YAML
sed 's/min: \[0.6, 0.2, 0.05\], max: \[0.75, 0.35, 0.2\]/min: [0.6, 0, 0.05], max: [0.75, 0.15, 0.2]/' "$work/box.yaml" > "$work/rest.yaml"
for scene in box rest; do
  expect ${scene}_full 0 'completed' -- "$surge" run "$work/$scene.yaml" --out "$work/${scene}_full" --progress quiet
  expect ${scene}_stopped 130 'interrupted' -- "$surge" run "$work/$scene.yaml" --out "$work/${scene}_part" --progress quiet --stop-at-step 120
  expect ${scene}_restart 0 'completed' -- "$surge" run "$work/$scene.yaml" --restart "$work/${scene}_part/checkpoints/box_push_step_000000037.h5" --progress quiet
done
# step 37 (t = 0.05 s): the box is 0.26 m up, in free fall, touching nothing.
expect box_bitwise 0 'numeric datasets' -- $compare "$work/box_full" "$work/box_part" box_push
expect rest_bitwise 0 'numeric datasets' -- $compare "$work/rest_full" "$work/rest_part" box_push

# 3. Refusals and --force.
newest=$(ls "$work"/full/checkpoints/dam_barrier_step_*.h5 | tail -1)
expect exists_refused 2 "full/dam_barrier\.h5' exists: pass --force to overwrite it, --out to write elsewhere, or --restart .*dam_barrier_step_[0-9]+\.h5" \
  -- "$surge" run "$work/dam.yaml" --out "$work/full" --progress quiet
{ cat "$work/dam.yaml"; echo "# edited"; } > "$work/dam_edited.yaml"
expect other_scene_refused 2 "checkpoint '.*dam_barrier_step_[0-9]+\.h5' was written from another scene \('.*/dam\.yaml', hash [0-9a-f]{16}\) than '.*/dam_edited\.yaml'" \
  -- "$surge" run "$work/dam_edited.yaml" --restart "$newest" --progress quiet
expect other_set_refused 2 'other --set overrides' \
  -- "$surge" run "$work/dam.yaml" --restart "$newest" --set time.end=0.4 --progress quiet
# The result-exists refusal comes before the scene is built: this cell size would otherwise be
# refused by the memory check (or seed for minutes).
expect exists_refused_before_seeding 2 "full/dam_barrier\.h5' exists: pass --force" \
  -- "$surge" run "$work/dam.yaml" --out "$work/full" --progress quiet --set grid.cell_size=1e-5
# A mesh file's content is part of the resolved scene (its FNV-1a hash): a restart after the
# mesh changed is refused naming the file.
mkdir -p "$work/meshes"
cp "$src/tests/data/meshes/unit_cube.obj" "$work/meshes/"
sed -e 's/^time: .*/time: {end: 0.01}/' -e 's|\.\./meshes/|meshes/|' -e '$a output: {checkpoint_every: 1.0}' \
  "$src/tests/data/scenes/mesh_cube.yaml" > "$work/mesh_cube.yaml"
expect mesh_stopped 130 'interrupted at t' -- "$surge" run "$work/mesh_cube.yaml" --out "$work/mesh" --progress quiet --stop-at-step 3
echo "# edited" >> "$work/meshes/unit_cube.obj"
expect mesh_changed_refused 2 "mesh file '.*/meshes/unit_cube\.obj' changed since checkpoint '.*mesh_cube_step_000000003\.h5' was written \(content hash [0-9a-f]{16}, now [0-9a-f]{16}\)" \
  -- "$surge" run "$work/mesh_cube.yaml" --restart "$work/mesh/checkpoints/mesh_cube_step_000000003.h5" --progress quiet
expect not_a_checkpoint 2 'is not a Surge checkpoint' \
  -- "$surge" run "$work/dam.yaml" --restart "$work/full/dam_barrier.h5" --out "$work/full" --progress quiet
expect missing_checkpoint 2 'no such file' \
  -- "$surge" run "$work/dam.yaml" --restart "$work/full/checkpoints/nothing.h5" --progress quiet
sed 's/^name: dam_barrier/name: ..\/escape/' "$work/dam.yaml" > "$work/escape.yaml"
expect name_with_path 2 "escape.yaml:[0-9]+:.*name.*may contain only letters" -- "$surge" check "$work/escape.yaml"
touch "$work/full/checkpoints/dam_barrier_step_999999999.h5"
expect force_overwrites 0 'completed' -- "$surge" run "$work/dam.yaml" --out "$work/full" --progress quiet --force --set time.end=0.05
if [ ! -e "$work/full/checkpoints/dam_barrier_step_999999999.h5" ]; then ok "force_clears_checkpoints"
else bad "force_clears_checkpoints: the old run's checkpoint is still there"; fi
finish restart

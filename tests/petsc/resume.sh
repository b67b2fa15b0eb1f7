#!/usr/bin/env bash
# fcm-sim --backend petsc --resume on a linear scene (label mpi): tests/petsc/scenes/
# vibrating_beam_euler.json (backward Euler, the linear driver's scheme) runs through the
# integrator on PETSc like every scene (fcm_simulation_run(), the serial checkpoint format).
#  - 10 steps on 2 processes (CG + GAMG to rtol 1e-12: MUMPS, the scene's direct solver, is not
#    bitwise reproducible between runs on 2 processes) with a checkpoint every 5, then a copy of its output resumed from
#    step 5 on 2 processes: the log (all but the wall-time column), the PVD and the frames'
#    pieces equal the uninterrupted run's byte for byte;
#  - checkpoints of the linear driver, of today's format (the serial container) and of its older
#    one (.fcmpk), written at step 5 by petsc_legacy_checkpoint, resume too: the step-10 state
#    equals the uninterrupted run's to 1e-8 relative;
#  - a checkpoint of another scene is refused (exit 2) on every process.
# Arguments: mpiexec, fcm-sim, petsc_state_diff, petsc_legacy_checkpoint, scene file, work dir.
set -euo pipefail
mpiexec=$1 sim=$2 diff=$3 legacy=$4 scene=$5 work=$6
name=vibrating_beam
ksp=(-ksp_type cg -pc_type gamg -ksp_rtol 1e-12)
rm -rf "$work" && mkdir -p "$work"
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/a" --steps 10 --checkpoint-every 5 -q \
  "${ksp[@]}"
ck5=${name}_checkpoint_000005.fcmck ck10=${name}_checkpoint_000010.fcmck
[ -f "$work/a/$ck5" ] && [ -f "$work/a/$ck10" ]
cp -r "$work/a" "$work/b"
rm "$work/b"/${name}_background_000[345]* "$work/b/$ck10"
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/b" --steps 10 --checkpoint-every 5 -q --resume "$work/b/$ck5" \
  "${ksp[@]}"
strip() { sed 's/,[^,]*$//' "$1"; }
diff <(strip "$work/a/${name}_log.csv") <(strip "$work/b/${name}_log.csv")
cmp "$work/a/${name}_background.pvd" "$work/b/${name}_background.pvd"
for f in "$work"/a/${name}_background_000[345]*; do cmp "$f" "$work/b/$(basename "$f")"; done
"$diff" "$work/a/$ck10" "$work/b/$ck10" 0
# the linear driver's state at step 5 (the older .fcmpk format, then the container), resumed
# to step 10
mkdir -p "$work/c"
(cd "$work/c" && "$mpiexec" -n 2 "$legacy" "${scene%/*}" "$(basename "$scene")" 5 "$work/c/old" keep \
  >/dev/null)
[ -f "$work/c/old_np2.fcmpk" ]
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/c" --steps 10 --checkpoint-every 5 -q \
  --resume "$work/c/old_np2.fcmpk" "${ksp[@]}"
"$diff" "$work/c/$ck10" "$work/a/$ck10" 1e-8
[ -f "$work/c/old_np2.fcmck" ]
rm "$work/c/$ck10"
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/c" --steps 10 --checkpoint-every 5 -q \
  --resume "$work/c/old_np2.fcmck" "${ksp[@]}"
"$diff" "$work/c/$ck10" "$work/a/$ck10" 1e-8
# a checkpoint of another scene is refused (exit 2) on every process
if "$mpiexec" -n 2 "$sim" "${scene%/*}/../../../apps/scenes/cantilever.json" --backend petsc -o "$work/d" -q \
     --resume "$work/a/$ck5" 2>"$work/err"; then
  echo "resume of another scene's checkpoint succeeded" >&2
  exit 1
fi
grep -q "different scene" "$work/err"
rm -rf "$work"

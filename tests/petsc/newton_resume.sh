#!/usr/bin/env bash
# Checkpoints of fcm-sim --backend petsc on the integrator path (label mpi): clamped_surface.json
# (Stable Neo-Hookean, Nitsche on the embedded boundary, gravity, damping; CG + GAMG to rtol
# 1e-12) with the scene's output.checkpoint_interval = 3, 6 steps on 2 processes; then
#  - the background frames are parallel (<name>_background_NNNN.pvtu + one piece per process,
#    indexed by the PVD);
#  - resumed from step 3 on 2 processes: the log (all but the wall-time column), both PVDs,
#    every frame (.pvtu, pieces, surface .vtu) and the step-6 checkpoint's state equal the
#    uninterrupted run's byte for byte;
#  - resumed on 1 process, and by the serial fcm-sim (the same .fcmck format): the step-6 state
#    equal to 1e-10 relative;
#  - --checkpoint-every 2 overrides the scene's interval; a checkpoint of another scene exits 2
#    on every process with the message.
# Arguments: mpiexec, fcm-sim, petsc_state_diff, scene file, work directory.
set -euo pipefail
mpiexec=$1 sim=$2 diff=$3 scene=$4 work=$5
name=clamped_surface
ksp=(-ksp_type cg -pc_type gamg -ksp_rtol 1e-12)
rm -rf "$work" && mkdir -p "$work"
sed 's/"frame_interval": 2/"frame_interval": 2, "checkpoint_interval": 3/' "$scene" >"$work/scene.json"
grep -q '"checkpoint_interval": 3' "$work/scene.json"
run() { "$mpiexec" -n "$1" "$sim" "$work/scene.json" --backend petsc -q --steps 6 "${@:2}" "${ksp[@]}"; }
run 2 -o "$work/a"
[ -f "$work/a/${name}_checkpoint_000003.fcmck" ] && [ -f "$work/a/${name}_checkpoint_000006.fcmck" ]
[ ! -e "$work/a/${name}_checkpoint_000002.fcmck" ]
# the background frames are parallel: a .pvtu naming one piece per process, in the PVD
[ -f "$work/a/${name}_background_0003.pvtu" ] && [ -f "$work/a/${name}_background_0003_1.vtu" ]
grep -q "${name}_background_0003.pvtu" "$work/a/${name}_background.pvd"
ck3=${name}_checkpoint_000003.fcmck ck6=${name}_checkpoint_000006.fcmck
# the same process count: byte for byte (frames at steps 0, 2, 4, 6; the checkpoint has 0, 2)
for d in b c; do
  cp -r "$work/a" "$work/$d"
  rm "$work/$d"/${name}_*_000[23].vtu "$work/$d"/${name}_*_000[23].pvtu \
    "$work/$d"/${name}_*_000[23]_*.vtu "$work/$d/$ck6"
done
run 2 -o "$work/b" --resume "$work/b/$ck3"
strip() { sed 's/,[^,]*$//' "$1"; }
diff <(strip "$work/a/${name}_log.csv") <(strip "$work/b/${name}_log.csv")
for f in "$work"/a/*.pvd "$work"/a/*.pvtu "$work"/a/*.vtu; do cmp "$f" "$work/b/$(basename "$f")"; done
"$diff" "$work/a/$ck6" "$work/b/$ck6" 0
# another process count, and the serial fcm-sim, from the same checkpoint: to 1e-10
run 1 -o "$work/c" --resume "$work/c/$ck3"
"$diff" "$work/c/$ck6" "$work/a/$ck6" 1e-10
mkdir -p "$work/d" && cp "$work/a/$ck3" "$work/d/"
"$sim" "$work/scene.json" -q --steps 6 -o "$work/d" --resume "$work/d/$ck3"
"$diff" "$work/d/$ck6" "$work/a/$ck6" 1e-10
# --checkpoint-every overrides the scene's interval
run 2 -o "$work/e" --checkpoint-every 2 --steps 4
[ -f "$work/e/${name}_checkpoint_000002.fcmck" ] && [ -f "$work/e/${name}_checkpoint_000004.fcmck" ]
[ ! -e "$work/e/$ck3" ]
# a checkpoint of another scene: exit 2 on every process, with the message
if "$mpiexec" -n 2 "$sim" "${scene%/*}/spinning_body.json" --backend petsc -q --steps 4 \
     -o "$work/f" --resume "$work/a/$ck3" 2>"$work/err"; then
  echo "resume of another scene's checkpoint succeeded" >&2
  exit 1
else
  rc=$?
  [ "$rc" -eq 2 ] || { echo "exit $rc, expected 2" >&2; exit 1; }
fi
grep -q "written by a different scene" "$work/err"
rm -rf "$work"

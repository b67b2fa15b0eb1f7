#!/usr/bin/env bash
# An example scene through `mpiexec -n 2 fcm-sim SCENE --backend petsc` against the serial
# `fcm-sim SCENE` (label mpi; the table of scenes is in tests/petsc/tests.cmake).
#   scene_app.sh run MPIEXEC FCM_SIM STATE_DIFF SCENE STEPS RTOL WORK
#     both take STEPS steps (--steps) with a checkpoint every step; the state of the last
#     checkpoint (displacement and velocity, .fcmck) agrees to RTOL relative
#     (petsc_state_diff); the KSP runs to -ksp_rtol 1e-12. The parallel frames
#     (<name>_background_NNNN.pvtu, one piece <name>_background_NNNN_<rank>.vtu per process,
#     indexed by the PVD) are checked: the last frame's
#     pieces' displacement and velocity (placed by node_index) and cell fields (stress, von
#     Mises, strain energy density, placed by cell_index) agree to RTOL with the serial frame.
#   scene_app.sh summary MPIEXEC FCM_SIM - SCENE - - WORK
#     the run summaries (--check, 3 steps) agree on the whole body's figures: the cells and
#     their cut-cell point counts, the volume, the rules built (stored points), the
#     constraints (embedded-boundary points) and the body's max |u| — the same lines; the
#     PETSc run's come from every process's cells (fcm_petsc_simulation_summary_view()).
#   scene_app.sh refused MPIEXEC FCM_SIM - SCENE - REGEX WORK
#     the backend refuses the scene: exit 2 on every process, the message matches REGEX
#     (grep -E), nothing is stepped.
# The distributed backend partitions a surface body by its volume mesh ("volume_mesh": "auto"
# builds one there), the serial run integrates it from the surface alone: the serial run
# takes the same scene with "volume_mesh": true, so both integrate the same cells alike.
set -euo pipefail
mode=$1 mpiexec=$2 sim=$3 diff=$4 scene=$5 steps=$6 arg=$7 work=$8
name=$(basename "$scene" .json)
rm -rf "$work" && mkdir -p "$work"
serial_scene=$work/serial/$name.json
make_serial_scene() {
  mkdir -p "$work/serial"
  "$sim" "$scene" --print-scene | sed 's/"volume_mesh": "auto"/"volume_mesh": true/' \
    >"$serial_scene"
}
if [ "$mode" = summary ]; then
  "$mpiexec" -n 2 "$sim" "$scene" --backend petsc --check -ksp_rtol 1e-12 >"$work/p.txt"
  make_serial_scene
  "$sim" "$serial_scene" --check >"$work/s.txt"
  pick() { grep -E '^  (cells|volume|body) |^  computed  (rules built|constraints) ' "$1"; }
  [ "$(pick "$work/s.txt" | wc -l)" -ge 4 ] || { echo "summary lines missing" >&2; exit 1; }
  diff <(pick "$work/s.txt") <(pick "$work/p.txt")
  rm -rf "$work"
  exit 0
fi
if [ "$mode" = refused ]; then
  set +e
  "$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/p" -q --steps 1 2>"$work/err"
  rc=$?
  set -e
  cat "$work/err"
  [ "$rc" -eq 2 ] || { echo "exit $rc, expected 2 (refused)" >&2; exit 1; }
  grep -Eq "$arg" "$work/err" || { echo "message does not match: $arg" >&2; exit 1; }
  rm -rf "$work"
  exit 0
fi
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/p" -q --steps "$steps" \
  --checkpoint-every 1 -ksp_rtol 1e-12
make_serial_scene
"$sim" "$serial_scene" -o "$work/s" -q --steps "$steps" --checkpoint-every 1
last() { ls "$1"/"$name"_checkpoint_* | sort | tail -n 1; }
a=$(last "$work/p") b=$(last "$work/s")
# the same step on both (the serial's last checkpoint names the step)
[ "${a%.*}" = "$work/p/$(basename "${b%.*}")" ] || { echo "last checkpoints $a, $b" >&2; exit 1; }
"$diff" "$a" "$b" "$arg"
ls "$work/p/${name}"_background_*.pvtu >/dev/null || { echo "no parallel frames" >&2; exit 1; }
f=$(ls "$work/p/${name}"_background_*.pvtu | sort | tail -n 1)
# one piece per process, and the PVD indexes the .pvtu frames
for r in 0 1; do [ -f "${f%.pvtu}_$r.vtu" ] || { echo "piece ${f%.pvtu}_$r.vtu missing" >&2; exit 1; }; done
grep -q "$(basename "$f")" "$work/p/${name}_background.pvd" || { echo "PVD lacks $f" >&2; exit 1; }
if ls "$work/p/${name}"_background_????.vtu >/dev/null 2>&1; then
  echo "serial background frames next to the .pvtu" >&2; exit 1
fi
"$diff" --vtu "$f" "$work/s/$(basename "${f%.pvtu}").vtu" "$arg"
rm -rf "$work"

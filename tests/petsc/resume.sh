#!/usr/bin/env bash
# fcm-sim --backend petsc --resume (label mpi): a 10-step run of vibrating_beam.json on 2
# processes with a checkpoint every 5 steps, then a copy of its output resumed from step 5 on 2
# processes: the log (all but the wall-time column), the PVD and the frames' pieces equal the
# uninterrupted run's byte for byte. Arguments: mpiexec, fcm-sim, scene file, work directory.
set -euo pipefail
mpiexec=$1 sim=$2 scene=$3 work=$4
rm -rf "$work" && mkdir -p "$work"
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/a" --steps 10 --checkpoint-every 5 -q
[ -f "$work/a/vibrating_beam_checkpoint_000005.fcmpk" ]
cp -r "$work/a" "$work/b"
rm "$work/b"/vibrating_beam_0003_* "$work/b"/vibrating_beam_0004_* "$work/b"/vibrating_beam_0005_*
"$mpiexec" -n 2 "$sim" "$scene" --backend petsc -o "$work/b" --steps 10 -q \
  --resume "$work/b/vibrating_beam_checkpoint_000005.fcmpk"
diff <(cut -d, -f1-7 "$work/a/vibrating_beam_log.csv") <(cut -d, -f1-7 "$work/b/vibrating_beam_log.csv")
cmp "$work/a/vibrating_beam.pvd" "$work/b/vibrating_beam.pvd"
for f in "$work"/a/vibrating_beam_000[345]_*.vtu; do cmp "$f" "$work/b/$(basename "$f")"; done
# a checkpoint of another scene is refused (exit 2) on every process
if "$mpiexec" -n 2 "$sim" "${scene%/*}/cantilever.json" --backend petsc -o "$work/c" -q \
     --resume "$work/a/vibrating_beam_checkpoint_000005.fcmpk" 2>"$work/err"; then
  echo "resume of another scene's checkpoint succeeded" >&2
  exit 1
fi
grep -q "another problem" "$work/err"
rm -rf "$work"

#!/bin/sh
# Runs the Dick et al. Table 1 scenes (octree against uniform, direct and multigrid) and
# prints per run: cells, DOFs, set-up and mean step time, iterations, peak memory, max |u|.
# usage: tests/bench/scenes/run_dick_table1.sh FCM_SIM [LEVELS...]   (default levels: 2 3; 4 takes 5 min, 5 another 6 min and 9 GiB)
# With CUT=1 the scenes with two cuts, dick_table1_cut_* (levels 2 3 4; no uniform level-4 direct
# scene), and each cut's time.
sim=${1:?usage: $0 FCM_SIM [LEVELS...]}; shift
dir=$(dirname "$0"); out=${TMPDIR:-/tmp}/fcm_dick_table1
levels=${*:-2 3}
for L in $levels; do for kind in octree uniform; do for sol in direct multigrid; do
  name=dick_table1_${CUT:+cut_}${kind}_L${L}_${sol}
  # no uniform level-5 direct scene: its factorization would not fit in 23 GiB
  [ -f "$dir/$name.json" ] || { echo "== $name: no scene, skipped"; continue; }
  /usr/bin/time -v "$sim" "$dir/$name.json" -o "$out/$name" > "$out.$name.txt" 2>&1 \
    || echo "$name: failed (exit $?), see $out.$name.txt"
  echo "== $name"
  grep -E 'DOFs|octree background|^  cells|computed  iterations|body      max|time \[s\]|step      \[s\]|^  cut [0-9]|Maximum resident' "$out.$name.txt"
done; done; done

#!/usr/bin/env bash
# The README's picture of the demo: the embedded surface of a run of the built-in scene
# (fcm-sim without a scene file, apps/scenes/twisting_cylinder.json) seen from the side, at a
# few frames, deformed (reference positions + displacement), drawn with gnuplot at true scale.
#   bash apps/docs/img/demo_side_view.sh OUTPUT_DIR PNG [TIME ...]
# OUTPUT_DIR: the run's output (twisting_cylinder_surface.pvd and its frames); PNG: the picture;
# TIME: the frames to draw, the one nearest each time in s (default 0 1 2 7). The picture in
# the README was made with
#   build/fcm-sim -o /tmp/demo -q && bash apps/docs/img/demo_side_view.sh /tmp/demo apps/docs/img/demo.png
# The frames are the VTU files fcm writes (raw appended data, UInt64 headers, Float64 points and
# displacement); the side view is the y-z plane (the tube's axis y across, gravity along -z).
set -euo pipefail
[ $# -ge 2 ] || {
  sed -n '2,11p' "$0"
  exit 2
}
dir=$1 png=$2
shift 2
times=("$@")
[ ${#times[@]} -gt 0 ] || times=(0 1 2 7)
pvd=$dir/twisting_cylinder_surface.pvd
[ -f "$pvd" ] || {
  echo "demo_side_view: $pvd not found (run fcm-sim -o $dir first)" >&2
  exit 1
}
command -v gnuplot >/dev/null || {
  echo "demo_side_view: gnuplot not found (Debian package gnuplot-nox)" >&2
  exit 1
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# "time file" per frame of the PVD index
sed -n 's/.*timestep="\([^"]*\)".*file="\([^"]*\)".*/\1 \2/p' "$pvd" >"$work/frames"
[ -s "$work/frames" ] || {
  echo "demo_side_view: no frame in $pvd" >&2
  exit 1
}

# The side view of one VTU frame: per ring of surface points (the points of one reference y),
# "y zmin zmax" of the deformed points, ordered along the tube: the tube's outline (its lower
# and upper edge seen from the side).
frame_points() { # vtu out
  local vtu=$1 out=$2 head start np off_u off_x
  head=$(grep -abo -m 1 '<AppendedData encoding="raw">' "$vtu" | sed -n '1s/:.*//p')
  # the data start after the '_' that follows the tag
  start=$(head -c "$((head + 256))" "$vtu" | tail -c 256 | grep -abo '_' | sed -n '1s/:.*//p')
  start=$((head + start + 1))
  head -c "$head" "$vtu" >"$work/xml"
  np=$(sed -n 's/.*NumberOfPoints="\([0-9]*\)".*/\1/p' "$work/xml" | head -n 1)
  off_u=$(sed -n 's/.*Name="displacement".*offset="\([0-9]*\)".*/\1/p' "$work/xml" | head -n 1)
  off_x=$(sed -n '/<Points>/,/<\/Points>/s/.*offset="\([0-9]*\)".*/\1/p' "$work/xml" | head -n 1)
  od -A n -v -t f8 -j "$((start + off_x + 8))" -N "$((np * 24))" "$vtu" | tr -s ' ' '\n' |
    sed '/^$/d' >"$work/x"
  od -A n -v -t f8 -j "$((start + off_u + 8))" -N "$((np * 24))" "$vtu" | tr -s ' ' '\n' |
    sed '/^$/d' >"$work/u"
  paste "$work/x" "$work/u" |
    awk '{ i = (NR - 1) % 3; x[i] = $1; v[i] = $1 + $2 }
      i == 2 { r = sprintf("%.3f", x[1]); n[r]++; y[r] += v[1]
               if (!(r in lo) || v[2] < lo[r]) lo[r] = v[2]
               if (!(r in hi) || v[2] > hi[r]) hi[r] = v[2] }
      END { for (r in n) print r, y[r] / n[r], lo[r], hi[r] }' | sort -g | cut -d' ' -f2- >"$out"
}

plot="" k=0
colours=("#1f77b4" "#d62728" "#2ca02c" "#ff7f0e" "#9467bd" "#8c564b")
for t in "${times[@]}"; do
  read -r ft file < <(awk -v t="$t" '{ d = $1 - t; d = d < 0 ? -d : d }
    NR == 1 || d < best { best = d; pick = $1 " " $2 } END { print pick }' "$work/frames")
  frame_points "$dir/$file" "$work/p$k"
  c=${colours[k % 6]}
  plot+="${plot:+, }'$work/p$k' using 1:3 with lines lw 2 lc rgb '$c' title sprintf('t = %.1f s',"
  plot+=" $ft), '' using 1:2 with lines lw 2 lc rgb '$c' notitle"
  k=$((k + 1))
done
gnuplot <<GP
set terminal png size 900,360 font ',11'
set output '$png.tmp'
set title 'the demo (fcm-sim, built-in scene) from the side: upper and lower edge of the 16 m tube'
set size ratio -1
set xrange [-9:9]
set yrange [-3.5:1.5]
set xtics 2
set ytics 1
set grid
set xlabel 'y (m), along the tube'
set ylabel 'z (m)'
set key bottom left opaque box
plot $plot
GP
mv "$png.tmp" "$png"

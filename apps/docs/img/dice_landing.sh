#!/usr/bin/env bash
# Pictures of the dice landing (apps/scenes/dice_on_floor.json): the embedded surface of the 36
# sticks (the cube's faces and both sides of every cut face, each moving with its stick) at a
# few frames, deformed (reference positions + displacement), as shaded 3D triangles with
# gnuplot (pm3d, depth-sorted), neighbouring sticks in different colours, the floor drawn at z = -0.3 m.
#   bash apps/docs/img/dice_landing.sh OUTPUT_DIR PNG [TIME ...]
# OUTPUT_DIR: the run's output (dice_on_floor_surface.pvd and its frames); PNG: the picture, one
# panel per TIME (the frame nearest each time in s; default 0 0.25 0.35 0.6). The picture
# apps/docs/img/dice_landing.png was made with
#   build/fcm-sim apps/scenes/dice_on_floor.json -o /tmp/dice -q &&
#   bash apps/docs/img/dice_landing.sh /tmp/dice apps/docs/img/dice_landing.png
# The frames are the VTU files fcm writes (raw appended data, UInt64 headers, Float64 points
# and displacement, Int64 connectivity); python3 (standard library) reads them.
set -euo pipefail
[ $# -ge 2 ] || {
  sed -n '2,13p' "$0"
  exit 2
}
dir=$1 png=$2
shift 2
times=("$@")
[ ${#times[@]} -gt 0 ] || times=(0 0.25 0.35 0.6)
pvd=$dir/dice_on_floor_surface.pvd
[ -f "$pvd" ] || {
  echo "dice_landing: $pvd not found (run fcm-sim apps/scenes/dice_on_floor.json -o $dir first)" >&2
  exit 1
}
command -v gnuplot >/dev/null || {
  echo "dice_landing: gnuplot not found (Debian package gnuplot-nox)" >&2
  exit 1
}
command -v python3 >/dev/null || {
  echo "dice_landing: python3 not found" >&2
  exit 1
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
sed -n 's/.*timestep="\([^"]*\)".*file="\([^"]*\)".*/\1 \2/p' "$pvd" >"$work/frames"
[ -s "$work/frames" ] || {
  echo "dice_landing: no frame in $pvd" >&2
  exit 1
}

# One frame's triangles, deformed, as gnuplot polygon blocks "x y z" (3 rows and a blank line
# each) into OUT_0 .. OUT_7 by colour: a stick's from the reference centre of its triangle
# (its column of the 6 x 6), so that neighbouring sticks differ.
cat >"$work/tri.py" <<'PY'
import re, struct, sys
vtu, out = sys.argv[1], sys.argv[2]
data = open(vtu, "rb").read()
tag = data.index(b'<AppendedData encoding="raw">')
start = data.index(b"_", tag) + 1
xml = data[:tag].decode()
def array(name, fmt, count):
    m = re.search(r'<DataArray type="\w+" Name="%s"[^>]*offset="(\d+)"' % name, xml)
    if m is None:
        m = re.search(r'<Points>\s*<DataArray[^>]*offset="(\d+)"', xml)
    off = start + int(m.group(1)) + 8
    return struct.unpack_from("<%d%s" % (count, fmt), data, off)
np_ = int(re.search(r'NumberOfPoints="(\d+)"', xml).group(1))
nc = int(re.search(r'NumberOfCells="(\d+)"', xml).group(1))
x = array("points", "d", 3 * np_)
u = array("displacement", "d", 3 * np_)
c = array("connectivity", "q", 3 * nc)
cuts = [0.13, 0.31, 0.5, 0.67, 0.86]
def column(v):
    return sum(v > q for q in cuts)
files = [open("%s_%d" % (out, k), "w") for k in range(8)]
for t in range(nc):
    ids = c[3 * t:3 * t + 3]
    ref = [sum(x[3 * i + k] for i in ids) / 3.0 for k in range(3)]
    f = files[(column(ref[0]) + 3 * column(ref[1])) % 8]
    for i in ids:
        f.write("%.5f %.5f %.5f\n" % tuple(x[3 * i + k] + u[3 * i + k] for k in range(3)))
    f.write("\n")
for f in files:
    f.close()
PY
n=${#times[@]} k=0 plots=""
colours=("#1f77b4" "#ff7f0e" "#2ca02c" "#d62728" "#9467bd" "#8c564b" "#e377c2" "#17becf")
for t in "${times[@]}"; do
  read -r ft file < <(awk -v t="$t" '{ d = $1 - t; d = d < 0 ? -d : d }
    NR == 1 || d < best { best = d; pick = $1 " " $2 } END { print pick }' "$work/frames")
  python3 "$work/tri.py" "$dir/$file" "$work/t$k"
  plots+="set title sprintf('t = %.2f s', $ft)"$'\n'
  plots+="splot '$work/floor' with polygons fc rgb '#dddddd' notitle"
  for c in 0 1 2 3 4 5 6 7; do
    plots+=", '$work/t${k}_$c' with polygons fc rgb '${colours[c]}' notitle"
  done
  plots+=$'\n'
  k=$((k + 1))
done
printf '%s\n' "-0.8 -0.8 -0.3" "1.8 -0.8 -0.3" "1.8 1.8 -0.3" "-0.8 1.8 -0.3" >"$work/floor"
gnuplot <<GP
set terminal png size $((420 * n)),460 font ',11'
set output '$png.tmp'
set multiplot layout 1,$n title 'dice\_on\_floor.json: 36 sticks of a diced cube land on a floor (contact between the pieces)'
set view 62, 35, 1.7
set view equal xyz
set xrange [-0.8:1.8]
set yrange [-0.8:1.8]
set zrange [-0.35:1.2]
unset xtics; unset ytics; unset ztics; unset border; unset colorbox
set pm3d depthorder border lc rgb '#333333' lw 0.5
$plots
unset multiplot
GP
mv "$png.tmp" "$png"

#!/usr/bin/env bash
# The README's picture command (apps/docs/img/demo_side_view.sh) on a short run of the demo's
# scene: fcm-sim without a scene file for 6 steps (frames at t = 0, 0.1, 0.2 s), then the
# side view of three frames; the result must be a PNG of the script's 900 x 360 pixels (its
# IHDR chunk). Without gnuplot the script must fail saying so (exit 77: skipped).
#   bash tests/apps/demo_picture.sh FCM_SIM SOURCE_DIR WORK_DIR
set -euo pipefail
sim=$1 src=$2 work=$3/demo-picture
rm -rf "$work"
"$sim" -o "$work" -q --steps 6
if ! command -v gnuplot >/dev/null; then
  ! bash "$src/apps/docs/img/demo_side_view.sh" "$work" "$work/side.png" 2>"$work/err"
  grep -q "gnuplot not found" "$work/err"
  exit 77
fi
bash "$src/apps/docs/img/demo_side_view.sh" "$work" "$work/side.png" 0 0.1 0.2
# signature, IHDR length and type, width and height (big-endian)
ihdr=$(od -A n -t x1 -N 24 "$work/side.png" | tr -d ' \n')
expect=89504e470d0a1a0a0000000d49484452$(printf '%08x%08x' 900 360)
if [ "$ihdr" != "$expect" ]; then
  echo "demo_picture: $work/side.png: header $ihdr, expected $expect" >&2
  exit 1
fi
echo "demo_picture: $work/side.png is a 900 x 360 PNG"

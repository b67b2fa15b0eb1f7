#!/usr/bin/env bash
# The dice pictures' command (apps/docs/img/dice_landing.sh) on a short run of
# apps/scenes/dice_on_floor.json: 3 steps (frames at t = 0, 0.01, 0.02, 0.03 s), then three
# panels; the result must be a PNG of the script's 3 x 420 x 460 pixels (its IHDR chunk).
# Without gnuplot the script must fail saying so (exit 77: skipped).
#   bash tests/apps/dice_picture.sh FCM_SIM SOURCE_DIR WORK_DIR
set -euo pipefail
sim=$1 src=$2 work=$3/dice-picture
rm -rf "$work"
"$sim" "$src/apps/scenes/dice_on_floor.json" -o "$work" -q --steps 3
if ! command -v gnuplot >/dev/null; then
  ! bash "$src/apps/docs/img/dice_landing.sh" "$work" "$work/dice.png" 2>"$work/err"
  grep -q "gnuplot not found" "$work/err"
  exit 77
fi
bash "$src/apps/docs/img/dice_landing.sh" "$work" "$work/dice.png" 0 0.01 0.03
# signature, IHDR length and type, width and height (big-endian)
ihdr=$(od -A n -t x1 -N 24 "$work/dice.png" | tr -d ' \n')
expect=89504e470d0a1a0a0000000d49484452$(printf '%08x%08x' 1260 460)
if [ "$ihdr" != "$expect" ]; then
  echo "dice_picture: $work/dice.png: header $ihdr, expected $expect" >&2
  exit 1
fi
echo "dice_picture: $work/dice.png is a 1260 x 460 PNG"

#!/bin/bash
# The deal.II interop example end to end: for each grid N^3, fcm writes the kinked body's rules
# and solves the problem itself (fcm_kinked); deal.II reads the rules, solves with FE_Q(p)^3 and
# reports its errors (dealii_kinked); at Q1 the two solutions must agree to 1e-10. Prints the
# errors and the rates between successive grids as a Markdown table.
#   convergence.sh [--check] FCM_KINKED DEALII_KINKED OUT_DIR [Q1_GRIDS [Q2_GRIDS]]
# Grids are space-separated lists (defaults "4 8 16 32" and "4 8 16"). --check (the ctest test
# interop_dealii) runs "4 8 16" and "4 8" and fails unless the finest rates are optimal:
# Q1 L2 >= 1.8, H1 >= 0.9; Q2 L2 >= 2.8, H1 >= 1.9 (strength 6 instead of 10 gives 1.86).
set -euo pipefail
check=0
if [ "${1:-}" = "--check" ]; then
  check=1
  shift
fi
fcm=$1 dealii=$2 out=$3
q1=${4:-"4 8 16 32"} q2=${5:-"4 8 16"}
if [ $check = 1 ]; then q1="4 8 16" q2="4 8"; fi
mkdir -p "$out"
fail=0
echo "| element | N | DOFs | L2 error | rate | H1 error | rate | max diff to fcm |"
echo "|---|---|---|---|---|---|---|---|"
for p in 1 2; do
  grids=$q1 strengths="4 6"
  # Q2 gradient products have total degree 10 (degree 2 per variable): strength 10 is exact
  if [ $p = 2 ]; then grids=$q2 strengths="10 10"; fi
  prev_l2="" prev_h1=""
  for n in $grids; do
    dir="$out/q$p"
    mkdir -p "$dir"
    # shellcheck disable=SC2086
    "$fcm" "$n" "$dir" $strengths > "$dir/fcm_$n.log"
    args=("$dir/rules_$n.fcmr" --degree "$p")
    if [ $p = 1 ]; then args+=(--compare "$dir/fcm_$n.txt" --tolerance 1e-10); fi
    if ! "$dealii" "${args[@]}" > "$dir/dealii_$n.log"; then
      cat "$dir/dealii_$n.log" >&2
      fail=1
    fi
    line=$(grep "L2 error" "$dir/dealii_$n.log")
    dofs=$(sed -E 's/.*Q[0-9], ([0-9]+) DOFs.*/\1/' <<< "$line")
    l2=$(sed -E 's/.*L2 error ([^,]+),.*/\1/' <<< "$line")
    h1=$(sed -E 's/.*H1 error ([^,]+),.*/\1/' <<< "$line")
    diff="-"
    if [ $p = 1 ]; then
      diff=$(sed -nE 's/.*solution ([^ ]+) .*/\1/p' "$dir/dealii_$n.log")
    fi
    r2="" rh=""
    if [ -n "$prev_l2" ]; then
      r2=$(awk -v a="$prev_l2" -v b="$l2" 'BEGIN { printf "%.2f", log(a / b) / log(2) }')
      rh=$(awk -v a="$prev_h1" -v b="$h1" 'BEGIN { printf "%.2f", log(a / b) / log(2) }')
    fi
    echo "| Q$p | $n | $dofs | $l2 | $r2 | $h1 | $rh | $diff |"
    prev_l2=$l2 prev_h1=$h1
  done
  if [ $check = 1 ]; then
    want_l2=$([ $p = 1 ] && echo 1.8 || echo 2.8) want_h1=$([ $p = 1 ] && echo 0.9 || echo 1.9)
    if ! awk -v r="$r2" -v w="$want_l2" -v s="$rh" -v v="$want_h1" 'BEGIN { exit !(r >= w && s >= v) }'; then
      echo "interop: Q$p rates L2 $r2 (want >= $want_l2), H1 $rh (want >= $want_h1)" >&2
      fail=1
    fi
  fi
done
exit $fail

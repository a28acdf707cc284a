#!/usr/bin/env bash
# compare_its.sh SLACK LAUNCHER... -- PROGRAM ARGS... -- RUN_A_ARGS... -- RUN_B_ARGS...
# Runs "LAUNCHER PROGRAM ARGS RUN_A_ARGS" and "... RUN_B_ARGS" with -ksp_converged_reason and passes when
# both converge and their iteration counts differ by at most SLACK (the MPI tests compare
# -mat_type binbcsr -ksp_type mcg against -mat_type aij -ksp_type cg this way).
set -u
slack=$1; shift
launcher=(); common=(); run_a=(); run_b=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do launcher+=("$1"); shift; done; shift
while [ $# -gt 0 ] && [ "$1" != "--" ]; do common+=("$1"); shift; done; shift
while [ $# -gt 0 ] && [ "$1" != "--" ]; do run_a+=("$1"); shift; done; shift
run_b=("$@")
its_of() {
  local out
  out=$("${launcher[@]}" "${common[@]}" "$@" -ksp_converged_reason 2>&1) || { echo "$out" >&2; return 1; }
  echo "$out" >&2
  echo "$out" | grep "Linear solve converged" | tail -1 | sed -E 's/.*iterations ([0-9]+).*/\1/' | grep -E '^[0-9]+$'
}
a=$(its_of "${run_a[@]}") || { echo "FAIL: run A (${run_a[*]}) did not converge"; exit 1; }
b=$(its_of "${run_b[@]}") || { echo "FAIL: run B (${run_b[*]}) did not converge"; exit 1; }
echo "A (${run_a[*]}): $a iterations; B (${run_b[*]}): $b iterations (slack $slack)"
diff=$((a > b ? a - b : b - a))
[ "$diff" -le "$slack" ] || { echo "FAIL: iteration counts differ by $diff"; exit 1; }

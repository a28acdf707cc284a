#!/usr/bin/env bash
# compare_its.sh SLACK [LAUNCHER...] -- PROGRAM [ARGS...]
# Runs PROGRAM with -ksp_type cg and with -ksp_type mcg (both with -ksp_converged_reason), and passes
# when both converge and their iteration counts differ by at most SLACK.
set -u
slack=$1; shift
launcher=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do launcher+=("$1"); shift; done
shift
its_of() { # prints the iteration count of the last "Linear solve converged" line, or fails
  local out
  out=$("${launcher[@]}" "$@" -ksp_converged_reason 2>&1) || { echo "$out" >&2; return 1; }
  echo "$out" >&2
  echo "$out" | grep "Linear solve converged" | tail -1 | sed -E 's/.*iterations ([0-9]+).*/\1/' | grep -E '^[0-9]+$'
}
cg=$(its_of "$@" -ksp_type cg) || { echo "FAIL: cg run did not converge"; exit 1; }
mcg=$(its_of "$@" -ksp_type mcg) || { echo "FAIL: mcg run did not converge"; exit 1; }
echo "cg: $cg iterations, mcg: $mcg iterations (slack $slack)"
diff=$((cg > mcg ? cg - mcg : mcg - cg))
[ "$diff" -le "$slack" ] || { echo "FAIL: iteration counts differ by $diff"; exit 1; }

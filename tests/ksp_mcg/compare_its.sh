#!/usr/bin/env bash
# compare_its.sh SLACK [LAUNCHER...] -- PROGRAM [ARGS...]
# Runs PROGRAM with -ksp_type cg and with -ksp_type mcg (both with -ksp_converged_reason and
# -ksp_view_final_residual), and passes when both converge, their iteration counts differ by at most
# SLACK, and mcg's answer is as good as cg's: its true final residual norm ||b - A x|| (recomputed by
# PETSc, not the recursion's estimate) and, where the program prints one (ksp ex4's "Norm of error"),
# its error norm are at most FACTOR (default 100) times cg's plus a floor of 1e-12 x cg's own residual
# scale (the norms of an exactly converged solve are rounding).
set -u
slack=$1; shift
factor=${COMPARE_FACTOR:-100}
launcher=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do launcher+=("$1"); shift; done
shift
run() { # prints "iterations residual error" of the last solve, or fails
  local out its res err
  out=$("${launcher[@]}" "$@" -ksp_converged_reason -ksp_view_final_residual 2>&1) || { echo "$out" >&2; return 1; }
  echo "$out" >&2
  its=$(echo "$out" | grep "Linear solve converged" | tail -1 | sed -E 's/.*iterations ([0-9]+).*/\1/' | grep -E '^[0-9]+$') || return 1
  res=$(echo "$out" | grep "KSP final norm of residual" | tail -1 | sed -E 's/.*residual ([^ ]+).*/\1/')
  err=$(echo "$out" | grep -E "Norm of error" | tail -1 | sed -E 's/.*Norm of error ([^ ,]+).*/\1/')
  echo "$its ${res:-none} ${err:-none}"
}
read -r cg cg_res cg_err < <(run "$@" -ksp_type cg) && [ -n "${cg:-}" ] || { echo "FAIL: cg run did not converge"; exit 1; }
read -r mcg mcg_res mcg_err < <(run "$@" -ksp_type mcg) && [ -n "${mcg:-}" ] || { echo "FAIL: mcg run did not converge"; exit 1; }
echo "cg: $cg iterations, residual $cg_res, error $cg_err; mcg: $mcg iterations, residual $mcg_res, error $mcg_err (slack $slack, factor $factor)"
diff=$((cg > mcg ? cg - mcg : mcg - cg))
[ "$diff" -le "$slack" ] || { echo "FAIL: iteration counts differ by $diff"; exit 1; }
[ "$cg_res" != none ] && [ "$mcg_res" != none ] || { echo "FAIL: no final residual norm printed"; exit 1; }
not_worse() { # not_worse WHAT MCG CG
  [[ $2 =~ ^[0-9.]+([eE][-+]?[0-9]+)?$ ]] || { echo "FAIL: mcg's $1 is $2"; exit 1; }
  awk -v m="$2" -v c="$3" -v f="$factor" 'BEGIN { m += 0; c += 0; exit !(m <= f * c + 1e-12 * (c > 1 ? c : 1)) }' ||
    { echo "FAIL: mcg's $1 $2 is more than $factor x cg's $3"; exit 1; }
}
not_worse "final residual norm" "$mcg_res" "$cg_res"
if [ "$cg_err" != none ]; then
  [ "$mcg_err" != none ] || { echo "FAIL: mcg run printed no error norm"; exit 1; }
  not_worse "error norm" "$mcg_err" "$cg_err"
fi
echo "ok"

#!/bin/bash
# summary_same.sh "KEY[:FLOOR] ..." RELTOL "COMMAND 1" "COMMAND 2" ...
# Runs each command (e.g. the same scene with -mat_type aij, baij, ..., or under mpiexec) and fails unless
# every listed summary key agrees with the first command's: |a - b| <= RELTOL |a| + FLOOR, where FLOOR is
# the key's own absolute floor (what counts as zero for that quantity, e.g. 1e-12 m for a joint error of
# 1e-10 m) and defaults to RELTOL (values of order 1). A key missing or not a number fails.
set -u
. "$(dirname "$0")/summary_lib.sh"
keys=$1; tol=$2; shift 2
names="" floors=""
for kf in $keys; do
  names="$names ${kf%%:*}"
  if [ "$kf" != "${kf#*:}" ]; then floors="$floors ${kf#*:}"; else floors="$floors $tol"; fi
done
ref=""
for variant in "$@"; do
  vals=$(summary_values "$variant" $names) || { printf '%s\n' "$vals"; exit 1; }
  echo "$variant:$vals"
  if [ -z "$ref" ]; then ref=$vals; continue; fi
  awk -v a="$ref" -v b="$vals" -v tol="$tol" -v keys="$names" -v floors="$floors" 'BEGIN { n = split(a, x, " "); split(b, y, " "); split(keys, k, " "); split(floors, f, " ");
    for (i = 1; i <= n; ++i) { d = x[i] - y[i]; if (d < 0) d = -d; s = x[i] < 0 ? -x[i] : x[i];
      if (d > tol * s + f[i]) { printf "FAIL: %s differs: %s vs %s (allowed %g)\n", k[i], x[i], y[i], tol * s + f[i]; exit 1 } } }' || exit 1
done
echo "ok: $keys agree within $tol (relative) plus each key's floor"

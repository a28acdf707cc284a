#!/bin/bash
# summary_same.sh "KEY ..." RELTOL "COMMAND 1" "COMMAND 2" ...
# Runs each command (e.g. the same scene with -mat_type aij, baij, ..., or under mpiexec) and fails unless
# every listed summary key agrees with the first command's within RELTOL (relative, with an absolute
# floor of RELTOL on values near zero).
set -u
keys=$1; tol=$2; shift 2
ref=""
for variant in "$@"; do
  out=$($variant 2>&1); rc=$?
  line=$(printf '%s\n' "$out" | grep '^summary ' | tail -n 1)
  if [ $rc -ne 0 ] || [ -z "$line" ]; then printf '%s\n' "$out" | tail -n 20; echo "FAIL: '$variant' exited with $rc / no summary"; exit 1; fi
  vals=""
  for k in $keys; do vals="$vals $(printf '%s\n' "$line" | tr ' ' '\n' | grep "^$k=" | cut -d= -f2)"; done
  echo "$variant:$vals"
  if [ -z "$ref" ]; then ref=$vals; continue; fi
  awk -v a="$ref" -v b="$vals" -v tol="$tol" -v keys="$keys" 'BEGIN { n = split(a, x, " "); split(b, y, " "); split(keys, k, " ");
    for (i = 1; i <= n; ++i) { d = x[i] - y[i]; if (d < 0) d = -d; s = x[i] < 0 ? -x[i] : x[i]; if (s < 1) s = 1;
      if (d > tol * s) { printf "FAIL: %s differs: %s vs %s\n", k[i], x[i], y[i]; exit 1 } } }' || exit 1
done
echo "ok: $keys agree within $tol"

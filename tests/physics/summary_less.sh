#!/bin/bash
# summary_less.sh KEY FACTOR "COMMAND A" "COMMAND B"
# Runs both commands and fails unless summary key KEY of A is below FACTOR times B's (both runs exiting
# 0 with a summary line): e.g. fewer CG iterations per solve with a setting than without it, measured
# with the PETSc at hand rather than against a count one PETSc version gives.
set -u
key=$1; factor=$2; shift 2
vals=""
for variant in "$@"; do
  out=$($variant 2>&1); rc=$?
  line=$(printf '%s\n' "$out" | grep '^summary ' | tail -n 1)
  if [ $rc -ne 0 ] || [ -z "$line" ]; then printf '%s\n' "$out" | tail -n 20; echo "FAIL: '$variant' exited with $rc / no summary"; exit 1; fi
  v=$(printf '%s\n' "$line" | tr ' ' '\n' | grep "^$key=" | cut -d= -f2)
  [[ $v =~ ^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$ ]] || { echo "FAIL: '$variant': $key is '${v}', not a number"; exit 1; }
  echo "$variant: $line"
  vals="$vals $v"
done
awk -v v="$vals" -v f="$factor" -v k="$key" 'BEGIN { split(v, x, " ");
  if (x[1] < f * x[2]) { printf "ok: %s %s < %s x %s\n", k, x[1], f, x[2]; exit 0 }
  printf "FAIL: %s %s is not below %s x %s\n", k, x[1], f, x[2]; exit 1 }'

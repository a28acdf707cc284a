#!/bin/bash
# summary_less.sh KEY FACTOR "COMMAND A" "COMMAND B"
# Runs both commands and fails unless summary key KEY of A is below FACTOR times B's (both runs exiting
# 0 with a summary line): e.g. fewer CG iterations per solve with a setting than without it, measured
# with the PETSc at hand rather than against a count one PETSc version gives.
set -u
. "$(dirname "$0")/summary_lib.sh"
key=$1; factor=$2; shift 2
vals=""
for variant in "$@"; do
  v=$(summary_values "$variant" "$key") || { printf '%s\n' "$v"; exit 1; }
  echo "$variant: $key=${v# }"
  vals="$vals $v"
done
awk -v v="$vals" -v f="$factor" -v k="$key" 'BEGIN { split(v, x, " ");
  if (x[1] < f * x[2]) { printf "ok: %s %s < %s x %s\n", k, x[1], f, x[2]; exit 0 }
  printf "FAIL: %s %s is not below %s x %s\n", k, x[1], f, x[2]; exit 1 }'

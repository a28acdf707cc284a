#!/bin/bash
# summary_check.sh 'AWK_CONDITION' -- PROGRAM ARGS...
# Runs the program, takes its last `summary key=value ...` line and fails unless the condition (an awk
# expression over the keys, e.g. 'nan==0 && joint_error_max<1e-6') holds. Prints the summary either way.
set -u
cond=$1; shift
[ "$1" = "--" ] && shift
out=$("$@" 2>&1); rc=$?
line=$(printf '%s\n' "$out" | grep '^summary ' | tail -n 1)
if [ $rc -ne 0 ] || [ -z "$line" ]; then
  printf '%s\n' "$out" | tail -n 30
  echo "FAIL: program exited with $rc or printed no summary line"; exit 1
fi
echo "$line"
prog=$(printf '%s\n' "$line" | awk '{ for (i = 2; i <= NF; ++i) { n = index($i, "="); k = substr($i, 1, n - 1); v = substr($i, n + 1);
  if (v !~ /^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$/) v = "\"" v "\""; printf "%s=%s; ", k, v } }')
awk "BEGIN { $prog if (!($cond)) { print \"FAIL: condition does not hold: $cond\"; exit 1 } print \"ok: $cond\" }"

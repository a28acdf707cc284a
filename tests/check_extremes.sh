#!/usr/bin/env bash
# check_extremes.sh [-energy_growth MAX] [-energy_max E] COMMAND...: a driver run at an extreme setting must end in a
# defined state: a `summary` line with no NaN or Inf in any value, nan=0 where the driver counts NaNs,
# and (with -energy_growth) a relative energy growth of at most MAX where the driver reports
# energy_growth_max; either exit status 0 with status=ok, or a solver failure the driver reports and
# stops on (exit status 2, status=solver_failed, ended=solver_failure@stepN): that is a defined outcome.
# An unstable or nonfinite run fails.
set -uo pipefail
growth="" emax=""
while :; do
  case "${1:-}" in
    -energy_growth) growth=$2; shift 2 ;;
    -energy_max) emax=$2; shift 2 ;;
    *) break ;;
  esac
done
out=$("$@" 2>&1)
rc=$?
summary=$(printf '%s\n' "$out" | grep '^summary ' | tail -1)
fail() { printf '%s\n' "$out" | tail -15; echo "check_extremes: $*"; exit 1; }
[ -n "$summary" ] || fail "no summary line (exit status $rc)"
if [ $rc = 2 ]; then
  echo "$summary" | grep -q ' ended=solver_failure@step[0-9]* status=solver_failed' || fail "exit status 2 without a reported solver failure"
else
  [ $rc = 0 ] || fail "exit status $rc"
fi
echo "$summary"
echo "$summary" | tr ' ' '\n' | grep -i -E '=(-?nan|-?inf)' && fail "NaN/Inf in the summary"
echo "$summary" | grep -q -E '(^| )nan=[1-9]' && fail "the driver counted NaNs"
if echo "$summary" | grep -q ' status='; then
  echo "$summary" | grep -q -E ' status=(ok|solver_failed)' || fail "status is not ok"
fi
if [ -n "$growth" ]; then
  g=$(echo "$summary" | tr ' ' '\n' | sed -n 's/^energy_growth_max=//p')
  [ -n "$g" ] || fail "no energy_growth_max reported"
  awk -v g="$g" -v m="$growth" 'BEGIN { exit !(g <= m) }' || fail "energy grew by $g (> $growth)"
fi
if [ -n "$emax" ]; then
  e=$(echo "$summary" | tr ' ' '\n' | awk -F= '$1 == "kinetic" || $1 == "elastic" { s += $2; n++ } END { if (n == 2) print s }')
  [ -n "$e" ] || fail "no kinetic/elastic energy reported"
  awk -v e="$e" -v m="$emax" 'BEGIN { exit !(e >= 0 && e <= m) }' || fail "kinetic + elastic energy $e outside [0, $emax]"
fi
exit 0

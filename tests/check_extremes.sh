#!/usr/bin/env bash
# check_extremes.sh [-energy_growth MAX] [-energy_max E] COMMAND...: a driver run at an extreme setting must end in a
# defined state: exit status 0 and a `summary` line with no NaN or Inf in any value, nan=0 where the
# driver counts NaNs, status=ok where it reports a status, and (with -energy_growth) a relative energy
# growth of at most MAX where the driver reports energy_growth_max. Solver trouble is allowed when the
# driver reports it (ksp_reason=DIVERGED_..., unconverged_steps=N): that is a defined outcome.
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
[ $rc = 0 ] || fail "exit status $rc"
[ -n "$summary" ] || fail "no summary line"
echo "$summary"
echo "$summary" | tr ' ' '\n' | grep -i -E '=(-?nan|-?inf)' && fail "NaN/Inf in the summary"
echo "$summary" | grep -q -E '(^| )nan=[1-9]' && fail "the driver counted NaNs"
if echo "$summary" | grep -q ' status='; then
  echo "$summary" | grep -q ' status=ok' || fail "status is not ok"
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

#!/usr/bin/env bash
# expect_run.sh EXIT REGEX [REGEX...] -- COMMAND...: runs the command and passes only when its exit
# status is EXIT (a number, or `nonzero` for any failure) and its output (stdout and stderr together)
# matches every REGEX (Perl syntax; `.` also matches newlines, as in CTest's PASS_REGULAR_EXPRESSION,
# which alone would ignore the exit status). Write a newline in a REGEX as \n (in CMake "\\n"): grep
# would take a literal one as the start of another pattern.
set -u
want=$1; shift
regexes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do regexes+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
out=$("$@" 2>&1); rc=$?
fail() { printf '%s\n' "$out" | tail -n 30; echo "FAIL: $*"; exit 1; }
if [ "$want" = nonzero ]; then
  [ $rc -ne 0 ] || fail "exit status 0, expected a failure"
else
  [ $rc -eq "$want" ] || fail "exit status $rc, expected $want"
fi
for r in "${regexes[@]}"; do
  printf '%s' "$out" | grep -Pzq -- "(?s)$r" || fail "output does not match: $r"
done
printf '%s\n' "$out" | grep -E '^(summary|error|warning)' | tail -n 5
echo "ok: exit status $rc, output matches"

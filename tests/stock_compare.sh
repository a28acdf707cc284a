#!/bin/sh
# Runs a stock PETSc program twice, as the reference (-mat_type aij, ...) and with the plug-in
# (-dll_append libpetscbinbcsr.so -mat_type binbcsr, ...), keeps the lines that carry results
# (norms, iteration counts, vectors), and requires them to agree: words equal, numbers equal up to
# a relative tolerance (different summation orders may move the last printed digits) or an absolute
# one (for quantities at rounding level, such as the error norm of an exactly solved system).
#
#   stock_compare.sh [--keep ERE] [--drop ERE] [--expect ERE] [--reject ERE] [--rtol R] [--atol A] \
#                    --ref 'command and arguments' --test 'command and arguments'
#
# --keep: lines to compare (default: all); --drop: lines to ignore; --strip: text removed from every
# line first (e.g. stored zeros in a matrix listing, which a fixed-pattern format keeps); --expect: a line the test run
# must print (e.g. proof that the plug-in's type was used); --reject: a line it must not print (e.g. a
# view of an internal object); --allow-empty: a program that prints
# nothing on success (and errors otherwise) may print nothing. Both runs must exit with status 0.
set -u
keep='.' drop='^$' strip='' expect='' reject='' rtol=1e-10 atol=0 ref='' test='' allow_empty=0
while [ $# -gt 0 ]; do
  case "$1" in
    --keep) keep=$2; shift 2 ;;
    --drop) drop=$2; shift 2 ;;
    --strip) strip=$2; shift 2 ;;
    --expect) expect=$2; shift 2 ;;
    --reject) reject=$2; shift 2 ;;
    --rtol) rtol=$2; shift 2 ;;
    --atol) atol=$2; shift 2 ;;
    --allow-empty) allow_empty=1; shift ;;
    --ref) ref=$2; shift 2 ;;
    --test) test=$2; shift 2 ;;
    *) echo "stock_compare: unknown argument $1" >&2; exit 2 ;;
  esac
done
[ -n "$ref" ] && [ -n "$test" ] || { echo "stock_compare: need --ref and --test" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

run() { # name command
  sh -c "$2" > "$out/$1.out" 2>&1
  rc=$?
  if [ $rc -ne 0 ]; then
    echo "stock_compare: the $1 run failed (exit $rc): $2"
    cat "$out/$1.out"
    exit 1
  fi
  if [ -n "$strip" ]; then sed -E "s/$strip//g" "$out/$1.out"; else cat "$out/$1.out"; fi |
    grep -E -e "$keep" | grep -v -E -e "$drop" > "$out/$1.kept"
}
run ref "$ref"
run test "$test"

if [ ! -s "$out/ref.kept" ] && [ $allow_empty = 0 ]; then
  echo "stock_compare: the reference run printed no line to compare"; cat "$out/ref.out"; exit 1
fi
if [ -n "$expect" ] && ! grep -q -E -e "$expect" "$out/test.out"; then
  echo "stock_compare: the test run did not print a line matching: $expect"; cat "$out/test.out"; exit 1
fi
if [ -n "$reject" ] && grep -q -E -e "$reject" "$out/test.out"; then
  echo "stock_compare: the test run printed a line matching: $reject"; cat "$out/test.out"; exit 1
fi
if [ ! -s "$out/ref.kept" ]; then
  [ ! -s "$out/test.kept" ] || { echo "stock_compare: the test run printed lines the reference did not:"; cat "$out/test.kept"; exit 1; }
  echo "stock_compare: both runs succeeded and printed nothing to compare"
  exit 0
fi
if ! awk -v rtol="$rtol" -v atol="$atol" '
  function abs(x) { return x < 0 ? -x : x }
  function isnum(s) { return s ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
  NR == FNR { ref[FNR] = $0; nref = FNR; next }
  {
    ntest = FNR
    if (FNR > nref) { print "extra line in the test run: " $0; bad = 1; next }
    a = ref[FNR]; b = $0
    gsub(/[,;:()\[\]]/, " ", a); gsub(/[,;:()\[\]]/, " ", b)
    na = split(a, ta, " "); nb = split(b, tb, " ")
    ok = (na == nb)
    for (i = 1; ok && i <= na; i++) {
      if (isnum(ta[i]) && isnum(tb[i])) {
        x = ta[i] + 0; y = tb[i] + 0
        if (abs(x - y) > atol + rtol * (abs(x) > abs(y) ? abs(x) : abs(y))) ok = 0
      } else if (ta[i] != tb[i]) ok = 0
    }
    if (!ok) { print "line " FNR " differs:\n  ref:  " ref[FNR] "\n  test: " $0; bad = 1 }
  }
  END {
    if (ntest < nref) { print "the test run printed " ntest " lines to compare, the reference " nref; bad = 1 }
    exit bad
  }' "$out/ref.kept" "$out/test.kept"; then
  echo "--- reference output"; cat "$out/ref.out"; echo "--- test output"; cat "$out/test.out"
  exit 1
fi
echo "stock_compare: $(wc -l < "$out/ref.kept") lines agree"
sed 's/^/  /' "$out/test.kept" | head -20

#!/usr/bin/env bash
# check_spmv_table.sh [-allow_skipped_binbcsr] CSV COMMAND...: runs an spmv_bench command with
# -csv CSV and checks that every matrix has a row for every format, each timed ("ok"), with a product
# that agrees with aij and a positive rate. -allow_skipped_binbcsr accepts binbcsr rows skipped with a
# note (for a build whose binbcsr lacks that case, e.g. the mpi type before it lands).
set -euo pipefail
allow_skip=0
if [ "$1" = -allow_skipped_binbcsr ]; then allow_skip=1; shift; fi
csv=$1; shift
rm -f "$csv"
"$@" -csv "$csv"
[ -s "$csv" ] || { echo "no CSV written"; exit 1; }
matrices=$(tail -n +2 "$csv" | cut -d, -f1 | sort -u)
[ -n "$matrices" ] || { echo "CSV has no rows"; exit 1; }
status=0
for m in $matrices; do
  for f in aij baij sbaij sell binbcsr binbcsr_single; do
    row=$(grep "^$m,$f," "$csv" || true)
    [ -n "$row" ] || { echo "missing row: $m $f"; status=1; continue; }
    st=${row##*,}
    case $f in
      binbcsr*) [ "$st" = ok ] || { [ $allow_skip = 1 ] && [ "$st" = skipped ]; } || { echo "$m $f not timed ($st)"; status=1; } ;;
      *) [ "$st" = ok ] || { echo "$m $f not timed ($st)"; status=1; } ;;
    esac
    if [ "$st" = ok ]; then
      # rel_err (column 21): the product agrees with aij (single storage: float accuracy).
      err=$(echo "$row" | cut -d, -f21)
      awk -v e="$err" -v f="$f" 'BEGIN { lim = (f == "binbcsr_single") ? 1e-5 : 1e-12; exit !(e >= 0 && e < lim) }' \
        || { echo "$m $f: product differs from aij by $err"; status=1; }
      gf=$(echo "$row" | cut -d, -f13)
      awk -v g="$gf" 'BEGIN { exit !(g > 0) }' || { echo "$m $f: no GFlop/s"; status=1; }
    fi
  done
done
exit $status

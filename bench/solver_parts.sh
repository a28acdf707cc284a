#!/usr/bin/env bash
# bench/solver_parts.sh BUILD OUT ITS QUICK [DRIVER_MATRIX...]: parts 3 and 4 of scripts/bench.
#
# Both run PETSc's own ksp tutorial ex72 (built unchanged from PETSc's example sources as
# build/stock/stock_ksp_ex72) with the plug-in loaded by -dll_append, on matrices saved as PETSc
# binary files: the solver is timed as a stock PETSc user would run it.
#
# Part 3 (seed Fig. 2.43): per-iteration time of aij+cg, binbcsr+cg and binbcsr+mcg, Jacobi, ITS
#   iterations with no convergence test (cg: -ksp_norm_type none -ksp_convergence_test skip; mcg:
#   -ksp_mcg_fixed_iterations), KSPSolve time from -log_view; min over 2 rounds of separate runs for
#   matrices below 1M nonzeros (where run-to-run noise is largest and a run costs little), one run
#   above (the time budget); speedup over aij+cg against nnz. Matrices: the 27-point stencil at
#   several sizes + driver dumps.
# Part 4 (seed Fig. 2.44): residual history (-ksp_monitor_true_residual, ||b - A x|| / ||b|| with
#   the matrix as stored) against iteration and against time (iteration x the unmonitored time per
#   iteration) for aij double + cg, binbcsr double + mcg and binbcsr single + mcg on one quadratic FE
#   system (the quadratic_47k dump; the stencil when the FEM driver is not there).
set -euo pipefail
b=$1 out=$2 its=$3 quick=$4
shift 4
drivers=("$@")
ex72=$b/stock/stock_ksp_ex72
plugin=$b/libpetscbinbcsr.so
note() { echo "  note: $*"; }
[ -x "$ex72" ] || cmake --build "$b" --target stock_ksp_ex72 -j2 >/dev/null 2>&1 || true
[ -x "$ex72" ] || { note "stock ex72 could not be built: parts 3 and 4 skipped"; exit 0; }
mdir=$out/matrices
mkdir -p "$mdir"

if [ "$quick" = 1 ]; then sizes=4,8,12,16; hist_its=100; rounds=1
else sizes=4,6,8,12,16,20; hist_its=200; rounds=2; fi
dfargs=()
for f in "${drivers[@]+"${drivers[@]}"}"; do dfargs+=(-f "$f"); done
# saves the stencils and records the nonzeros of every matrix of part 3
"$b/examples/spmv_bench" -stats_only -formats aij -stencil_sizes $sizes -save_dir "$mdir" \
  "${dfargs[@]+"${dfargs[@]}"}" -csv "$mdir/stats.csv" >/dev/null

# combo -> ex72 options
combo_opts() {
  case $1 in
    aij_cg) echo "-ksp_type cg -ksp_norm_type none -ksp_convergence_test skip" ;;
    binbcsr_cg) echo "-mat_convert_type binbcsr -ksp_type cg -ksp_norm_type none -ksp_convergence_test skip" ;;
    binbcsr_mcg) echo "-mat_convert_type binbcsr -ksp_type mcg -ksp_mcg_fixed_iterations $its" ;;
  esac
}

# run_ex72 MATRIX LOG OPTIONS...: seconds per iteration of the KSPSolve (from -log_view), or empty
run_ex72() {
  local m=$1 log=$2
  shift 2
  if ! "$ex72" -f0 "$m" -rhs 0 -dll_append "$plugin" -pc_type jacobi -ksp_max_it "$its" "$@" \
       -log_view ":$log.perf" >"$log" 2>&1; then
    return 1
  fi
  local n
  n=$(sed -n 's/^Number of iterations = *\([0-9]*\).*/\1/p' "$log" | tail -1)
  awk -v n="${n:-0}" '$1 == "KSPSolve" && n > 0 { printf "%.6e\n", $4 / $2 / n; exit }' "$log.perf"
}

matrices=()
for n in ${sizes//,/ }; do matrices+=("$mdir/stencil$n.bin"); done
# -quick: the stencils only (the driver systems take most of the time at 200+ iterations)
[ "$quick" = 1 ] || matrices+=("${drivers[@]+"${drivers[@]}"}")

echo "matrix,nnz,combo,sec_per_it,speedup_vs_aij_cg" >"$out/cg_speedup.csv"
for m in "${matrices[@]}"; do
  name=$(basename "$m" .bin)
  nnz=$(awk -F, -v m="$name" '$1 == m || $1 == m".bin" { print $4; exit }' "$mdir/stats.csv")
  # The suite's time budget: 1000 iterations on the Bunny-class system alone would take minutes.
  if [ -n "$nnz" ] && [ "$nnz" -gt 5000000 ]; then note "$name: $nnz nonzeros, left out of part 3 (time budget)"; continue; fi
  declare -A best=()
  r_here=$rounds
  [ -n "$nnz" ] && [ "$nnz" -gt 1000000 ] && r_here=1
  for r in $(seq $r_here); do
    for c in aij_cg binbcsr_cg binbcsr_mcg; do
      # shellcheck disable=SC2046
      t=$(run_ex72 "$m" "$out/ksp_${name}_$c.log" $(combo_opts $c)) || { note "$name $c failed (see $out/ksp_${name}_$c.log)"; continue; }
      [ -n "$t" ] || continue
      if [ -z "${best[$c]:-}" ] || awk -v a="$t" -v b="${best[$c]}" 'BEGIN { exit !(a < b) }'; then best[$c]=$t; fi
    done
  done
  for c in aij_cg binbcsr_cg binbcsr_mcg; do
    [ -n "${best[$c]:-}" ] || continue
    sp=$(awk -v a="${best[aij_cg]:-0}" -v b="${best[$c]}" 'BEGIN { if (a > 0) printf "%.3f", a / b }')
    echo "$name,$nnz,$c,${best[$c]},$sp" >>"$out/cg_speedup.csv"
  done
  unset best
done
{
  echo "matrix nnz aij+cg_ms/it binbcsr+cg_ms/it binbcsr+mcg_ms/it binbcsr+cg_speedup binbcsr+mcg_speedup"
  awk -F, 'NR > 1 { key = $1; nnz[key] = $2; t[key, $3] = $4; s[key, $3] = $5; if (!(key in seen)) { seen[key] = 1; order[++n] = key } }
    END { for (i = 1; i <= n; i++) { k = order[i];
      printf "%s %s %.4f %.4f %.4f %s %s\n", k, nnz[k], 1e3 * t[k, "aij_cg"], 1e3 * t[k, "binbcsr_cg"], 1e3 * t[k, "binbcsr_mcg"], s[k, "binbcsr_cg"], s[k, "binbcsr_mcg"] } }' "$out/cg_speedup.csv"
} | column -t | sed 's/^/  /'
awk -F, 'NR > 1 && $3 != "aij_cg" { print $2, $5 > ("'"$out"'/cg_speedup_" $3 ".dat") }' "$out/cg_speedup.csv"
for c in binbcsr_cg binbcsr_mcg; do
  [ -f "$out/cg_speedup_$c.dat" ] && sort -n -o "$out/cg_speedup_$c.dat" "$out/cg_speedup_$c.dat"
done
if [ -s "$out/cg_speedup_binbcsr_cg.dat" ]; then
  gnuplot <<EOF
set terminal pngcairo size 900,550 font ",10"
set output "$out/cg_speedup.png"
set title "CG, $its iterations, Jacobi, no convergence test: speedup over aij + cg (seed Fig. 2.43 analog)" noenhanced
set xlabel "nonzeros"
set ylabel "speedup (time per iteration of aij+cg / ours)"
set logscale x
set grid
set key top left
set yrange [0:*]
plot 1 title "aij + cg" lw 2 lc rgb "red", \
     "$out/cg_speedup_binbcsr_cg.dat" using 1:2 with linespoints lw 2 pt 7 lc rgb "black" title "binbcsr + cg", \
     "$out/cg_speedup_binbcsr_mcg.dat" using 1:2 with linespoints lw 2 pt 5 lc rgb "blue" title "binbcsr + mcg"
EOF
  echo "  wrote $out/cg_speedup.csv, $out/cg_speedup.png"
fi

# ---- part 4: residual histories -------------------------------------------------------------
echo
system=""
for m in "${drivers[@]+"${drivers[@]}"}"; do
  case $(basename "$m") in quadratic_47k.bin) system=$m ;; esac
done
if [ -z "$system" ]; then
  system=$mdir/stencil$(echo ${sizes//,/ } | awk '{ print $NF }').bin
  note "quadratic FE system not available (examples/fem not on main or no dump): using $(basename "$system")"
fi
sname=$(basename "$system" .bin)
echo "Figure 2.44 analog: residual history on $sname, $hist_its iterations"
# label | ex72 options (single storage needs MatLoad into binbcsr: -mat_type binbcsr)
hist_cases=(
  "aij_double_cg|-ksp_type cg -ksp_norm_type none -ksp_convergence_test skip"
  "binbcsr_double_mcg|-mat_type binbcsr -ksp_type mcg -ksp_mcg_fixed_iterations $hist_its"
  "binbcsr_single_mcg|-mat_type binbcsr -mat_binbcsr_precision single -ksp_type mcg -ksp_mcg_fixed_iterations $hist_its"
)
labels=()
for hc in "${hist_cases[@]}"; do
  IFS='|' read -r label opts <<<"$hc"
  log=$out/history_${sname}_$label.log
  # shellcheck disable=SC2086
  if ! t=$(its=$hist_its run_ex72 "$system" "$log.timing" $opts); then
    note "$label: ex72 failed ($(grep -m1 -o 'No method [a-z]* for Mat of type [a-z]*' "$log.timing" || echo "see $log.timing")), skipped"
    continue
  fi
  # shellcheck disable=SC2086
  "$ex72" -f0 "$system" -rhs 0 -dll_append "$plugin" -pc_type jacobi -ksp_max_it $hist_its $opts \
    -ksp_monitor_true_residual >"$log" 2>&1 || { note "$label: monitored run failed"; continue; }
  awk -v t="$t" '/true resid norm/ { for (i = 1; i <= NF; i++) if ($i == "||r(i)||/||b||") print $1, $1 * t * 1e3, $(i + 1) }' \
    "$log" >"$out/history_$label.dat"
  labels+=("$label")
  last=$(tail -1 "$out/history_$label.dat")
  echo "  $label: $(printf '%.4f' "$(awk -v t="$t" 'BEGIN { print t * 1e3 }')") ms/iteration, after $hist_its iterations ||r||/||b|| = ${last##* }"
done
if [ ${#labels[@]} -gt 0 ]; then
  plots_it="" plots_t=""
  for l in "${labels[@]}"; do
    plots_it+="\"$out/history_$l.dat\" using 1:3 with lines lw 2 title \"$l\", "
    plots_t+="\"$out/history_$l.dat\" using 2:3 with lines lw 2 title \"$l\", "
  done
  gnuplot <<EOF
set terminal pngcairo size 1000,800 font ",10"
set output "$out/residual_history.png"
set multiplot layout 2,1 title "CG residual on $sname, Jacobi (seed Fig. 2.44 analog)" noenhanced
set logscale y
set format y "10^{%L}"
set grid
set key top right noenhanced
set ylabel "||b - A x|| / ||b||"
set xlabel "iteration"
plot ${plots_it%, }
set xlabel "time (ms, from the unmonitored time per iteration)"
plot ${plots_t%, }
unset multiplot
EOF
  echo "  wrote $out/history_*.dat, $out/residual_history.png"
fi

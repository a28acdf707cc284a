#!/usr/bin/env bash
# bench/readme_table.sh OUT_DIR RUN_NAME: the README's results table, as markdown, from one
# scripts/bench run's spmv.csv and steps.csv, headed by the machine it ran on (CPU model, cores,
# STREAM triad bandwidth measured by the same run) and the PETSc, date and commit. Writes
# OUT_DIR/readme_table.md.
set -euo pipefail
out=$1
run=$2
spmv=$out/spmv.csv
steps=$out/steps.csv
[ -s "$spmv" ] || { echo "readme_table: no $spmv" >&2; exit 1; }

cpu=$(lscpu 2>/dev/null | sed -n 's/^Model name: *//p' | head -1)
# VMs of several CPU generations share one model name ("AMD EPYC" on Zen 3, 4 and 5): the family and
# model say which one the figures come from.
family=$(lscpu 2>/dev/null | sed -n 's/^CPU family: *//p' | head -1)
model=$(lscpu 2>/dev/null | sed -n 's/^Model: *//p' | head -1)
[ -n "$cpu" ] && [ -n "$family" ] && cpu="$cpu (family $family model ${model:-?})"
triad=$(awk -F, 'NR > 1 && $NF == "ok" && $22 > best { best = $22 } END { if (best) printf "%.1f", best }' "$spmv")
readbw=$(awk -F, 'NR > 1 && $NF == "ok" && $24 > best { best = $24 } END { if (best) printf "%.1f", best }' "$spmv")
petsc=$(pkg-config --modversion PETSc 2>/dev/null || echo "?")
commit=$(git rev-parse --short HEAD 2>/dev/null || echo "?")

{
  echo "Machine: ${cpu:-unknown CPU}, $(nproc) cores; one core reads ${readbw:-?} GB/s (best access pattern; STREAM triad ${triad:-?} GB/s), measured by the same run;"
  echo "PETSc $petsc; $(date -u +%Y-%m-%d), commit $commit; \`$run\`."
  echo
  echo "| matrix | rows | SpMV GFlop/s: aij | baij | binbcsr | binbcsr single | binbcsr x aij | x baij | binbcsr % of read bw | ms per step: aij + cg | binbcsr + mcg | step speedup |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
  # one row per matrix of the SpMV run (driver dumps as scene.bin); the scene's 1-rank step times beside it
  awk -F, -v steps="$steps" '
    BEGIN {
      while ((getline line < steps) > 0) {
        split(line, f, ",")
        if (f[3] == "1") { aij[f[1] ".bin"] = f[4]; bin[f[1] ".bin"] = f[5]; sp[f[1] ".bin"] = f[6] }
      }
    }
    NR > 1 && $NF == "ok" {
      m = $1
      if (!(m in rows)) { order[++n] = m; rows[m] = $3 }
      g[m, $2] = $13
      if ($2 == "binbcsr") { xa[m] = $18; xb[m] = $19; pct[m] = $23 }
    }
    function v(x) { return x == "" ? "-" : x }
    function num(x) { return x == "" ? "-" : sprintf("%.2f", x) }
    END {
      for (i = 1; i <= n; i++) {
        m = order[i]; name = m; sub(/\.bin$/, "", name)
        printf "| %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", name, rows[m],
          num(g[m, "aij"]), num(g[m, "baij"]), num(g[m, "binbcsr"]), num(g[m, "binbcsr_single"]),
          v(xa[m]), v(xb[m]), (pct[m] == "" ? "-" : sprintf("%.0f", pct[m])), v(aij[m]), v(bin[m]), v(sp[m])
      }
    }' "$spmv"
  echo
  echo "SpMV: one rank, minimum over the rounds, GFlop/s = 2 nnz / time; binbcsr tuned on this machine"
  echo "(double, whole storage); % of read bw: the bytes the format stores (padding included) plus x and y"
  echo "against the best one-core read of a large array (above 100%: the matrix, or part of it, fits in"
  echo "the cache). Steps: one rank, the scene's options file, 30 CG"
  echo "iterations per step (the bridge: IC(0)-CG to its tolerance), aij + cg against binbcsr + mcg."
} >"$out/readme_table.md"
echo "  wrote $out/readme_table.md"

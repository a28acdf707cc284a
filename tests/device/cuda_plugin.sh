#!/usr/bin/env bash
# cuda_plugin.sh COMPARE_ITS PROGRAM PLUGIN: for a plug-in built with -DBINBCSR_CUDA=ON. Where a CUDA
# device answers (nvidia-smi lists one), ksp ex4 (PROGRAM) solved by KSPMCG on the device copy
# (-mat_binbcsr_device cuda) must converge as KSPCG on the host does (COMPARE_ITS, tests/ksp_mcg); where
# none does, the option must stop the program with a PETSc error naming why, not crash or fall back.
set -u
compare=$1 program=$2 plugin=$3
args=(-bs 3 -m 20 -n 20 -mat_type binbcsr -mat_binbcsr_device cuda -pc_type jacobi -dll_append "$plugin")
if command -v nvidia-smi > /dev/null 2>&1 && nvidia-smi -L 2> /dev/null | grep -q '^GPU '; then
  echo "a CUDA device answers: the solve runs on it"
  exec "$compare" 1 -- "$program" "${args[@]}"
fi
out=$("$program" "${args[@]}" -ksp_type mcg 2>&1)
rc=$?
echo "$out" | tail -n 20
[ $rc -ne 0 ] || { echo "FAIL: no CUDA device here, yet -mat_binbcsr_device cuda ran (exit 0)"; exit 1; }
[ $rc -lt 128 ] || { echo "FAIL: killed by signal $((rc - 128))"; exit 1; }
echo "$out" | grep -Eq -- '-mat_binbcsr_device cuda: (no usable CUDA device|no CUDA device on this machine)' ||
  { echo "FAIL: the error does not say that no CUDA device is there"; exit 1; }
echo "ok: no CUDA device, and the option says so (exit $rc)"

// binbcsr_tune -sweep: every (bin width, stream count, kernel body set, prefetch distance, x load) of MATSEQBINBCSR against the autotuned default
// (-mat_binbcsr_tune auto, nothing set) on one matrix, whole and symmetric storage, double and single
// precision, timed round-robin in one run; prints per case the sweep's best, the tuned choice and
// tuned / best, with seqbaij (seqaij for bs 1) as the reference.
#pragma once
#include <petscmat.h>
#include <string>
#include <vector>

struct SweepSettings {
  PetscInt repeats = 5; // rounds
  PetscInt batch   = 5; // MatMults per variant per round
  // Rounds of the head-to-head after the sweep: the tuned matrix against the sweep's best, alternating,
  // timed afresh (0: none). The best is the lowest of ~100 medians, so the sweep's own rounds flatter
  // it; the fresh rounds do not (the ratio reported as "confirmed").
  PetscInt  confirm    = 9;
  PetscBool tune_cache = PETSC_FALSE; // the tuned matrix may use the cache file (default: it measures)
  PetscBool verbose    = PETSC_FALSE; // every variant's time, not only the summary line
  std::vector<PetscInt> prefetches = {0, 1024, 4096}; // software prefetch distances swept (bytes)
  double (*now)()                  = nullptr;         // the clock
};

// A MATSEQBINBCSR copy of the assembled seq matrix src (its rows through MatSetValues) with block size
// bs; bw, streams: 0 = not set; tune: whether the layout build may tune.
PetscErrorCode MakeBinBCSR(Mat src, PetscInt bs, PetscInt bw, PetscInt streams, MatBinBCSRPrecision prec,
                           PetscBool sym, PetscBool tune, Mat *A);

// The sweep on one matrix (seq aij, block size set), named name in the output.
PetscErrorCode TuneSweep(const std::string &name, Mat aij, const SweepSettings &s);

// binbcsr_tune: MatMult of MATSEQBINBCSR for several bin widths, both precisions and several stream
// counts (MatBinBCSRSetStreams) against seqbaij and seqaij on the 27-point 3x3-block stencil, timed
// round-robin in one run (so load from other processes hits all variants alike); reports the minimum
// over the rounds. This is the measurement behind the default bin width and stream count
// (docs/mat_binbcsr.md).
//
//   binbcsr_tune [-stencil_n 48] [-bin_widths 1,2,4,8,16,32] [-streams 4] [-repeats 15] [-batch 10]
//                [-bs 3] [-coo] [-timer cpu|wall]
//
// -streams 1,2,4,8 times each matrix with each stream count (one matrix per width and precision:
// the stream count is a traversal order, set before each batch).
//
// -sweep: every (bin width 4/8/16(/32 for bs 1), streams 1/2/4/8, body set the CPU has, prefetch distance
// 0/1024/4096 bytes or those of -sweep_prefetch) against the autotuned default
// (nothing set, -mat_binbcsr_tune auto) for whole and symmetric storage in double and single precision,
// on the stencils of -stencil_sizes (default 32,48; or the one of -stencil_n) and on every PETSc binary
// file of -f (comma list, block size from -bs, default 3; the drivers write them with -dump_matrix FILE).
// Per matrix and case one line: the sweep's best bw/K/body and ms, the tuned bw/K/body and ms, tuned /
// best, the reference (seqbaij; seqaij for bs 1) and what the tuning cost. The best is then timed again
// against the tuned matrix alone, alternating, -sweep_confirm N rounds (default 9; 0: not), since the
// lowest of ~100 medians is biased low by the rounds that chose it. -sweep_verbose prints every variant;
// -tune_cache 1 lets the tuned matrix use the cache file (default: it measures).
//
// The fixed variants are built with -mat_binbcsr_tune off semantics (MatBinBCSRSetTune).
//
// -bs 1 measures BIN-CSR on the same stencil seen as a scalar matrix.
// -coo also times the COO refill (MatSetValuesCOO, INSERT) of seqaij and binbcsr (default bin width,
// both precisions) with the COO list of trilinear hexahedra on the same node grid (24x24 element
// matrices, every entry listed once per element).
#include <petscbinbcsr.h>
#include "sim/stencil.h"
#include "sim/bench_util.h"
#include "sim/matrix_file.h"
#include "sim/tune_sweep.h"
#include <algorithm>
#include <ctime>
#include <string>
#include <vector>

namespace {
/* This thread's CPU time, the tuner's clock: on a machine shared with other jobs it leaves out the
   time we are descheduled (memory contention still counts). -timer wall switches to MPI_Wtime. */
PetscBool use_wall = PETSC_FALSE;
double    Now()
{
  if (use_wall) return MPI_Wtime();
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct Variant {
  std::string name;
  Mat         A       = nullptr;
  PetscInt    streams = 0;    /* MatBinBCSRSetStreams before each batch; 0: aij/baij */
  bool        owner   = true; /* destroys A (binbcsr matrices are shared by their stream counts) */
  double      best    = 1e300;
};

/* COO refill of the hexahedral element list on the grid: seqaij against binbcsr (both precisions). */
PetscErrorCode TimeCOO(const StencilGrid &g, PetscInt repeats)
{
  const PetscInt        n = 3 * g.nodes();
  std::vector<PetscInt> ci, cj;
  auto                  id = [&](PetscInt x, PetscInt y, PetscInt z) { return (z * g.ny + y) * g.nx + x; };

  PetscFunctionBeginUser;
  for (PetscInt z = 0; z + 1 < g.nz; z++)
    for (PetscInt y = 0; y + 1 < g.ny; y++)
      for (PetscInt x = 0; x + 1 < g.nx; x++) {
        PetscInt nodes[8], q = 0;
        for (PetscInt c = 0; c < 8; c++) nodes[q++] = id(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2));
        for (PetscInt a = 0; a < 24; a++)
          for (PetscInt b = 0; b < 24; b++) {
            ci.push_back(3 * nodes[a / 3] + a % 3);
            cj.push_back(3 * nodes[b / 3] + b % 3);
          }
      }
  std::vector<PetscScalar> v(ci.size());
  for (size_t k = 0; k < v.size(); k++) v[k] = 1.0 + 1e-3 * (double)(k % 977);
  const char *names[3] = {"seqaij", "binbcsr double", "binbcsr single"};
  Mat         M[3];
  double      best[3] = {1e300, 1e300, 1e300};
  for (int t = 0; t < 3; t++) {
    std::vector<PetscInt> i = ci, j = cj;
    PetscCall(MatCreate(PETSC_COMM_SELF, &M[t]));
    PetscCall(MatSetSizes(M[t], n, n, n, n));
    PetscCall(MatSetBlockSize(M[t], 3));
    PetscCall(MatSetType(M[t], t ? MATSEQBINBCSR : MATSEQAIJ));
    if (t == 2) PetscCall(MatBinBCSRSetPrecision(M[t], MAT_BINBCSR_PRECISION_SINGLE));
    PetscCall(MatSetPreallocationCOO(M[t], (PetscCount)i.size(), i.data(), j.data()));
  }
  for (PetscInt r = 0; r < repeats; r++)
    for (int t = 0; t < 3; t++) {
      const double t0 = Now();
      PetscCall(MatSetValuesCOO(M[t], v.data(), INSERT_VALUES));
      best[t] = PetscMin(best[t], Now() - t0);
    }
  PetscCall(PetscPrintf(PETSC_COMM_SELF,
                        "COO refill (MatSetValuesCOO INSERT, %zu entries from %" PetscInt_FMT
                        " hexahedra), minimum over %" PetscInt_FMT " calls\n",
                        ci.size(), (g.nx - 1) * (g.ny - 1) * (g.nz - 1), repeats));
  for (int t = 0; t < 3; t++)
    PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-16s %10.4f ms %8.2f x aij\n", names[t], 1e3 * best[t],
                          best[0] / best[t]));
  for (int t = 0; t < 3; t++) PetscCall(MatDestroy(&M[t]));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  StencilGrid grid;
  // the lists have one place more than they may hold: PETSc drops what does not fit without a word
  PetscInt             widths[17] = {1, 2, 4, 8, 16, 32}, nw = 6, repeats = 15, batch = 10, bs = 3;
  PetscInt             streams[5] = {4}, ns = 1;
  PetscBool            coo = PETSC_FALSE;
  std::vector<Variant> vars;
  Mat                  aij, baij;
  Vec                  x, y;

  PetscCall(PetscInitialize(&argc, &argv, nullptr, nullptr));
  PetscCall(PetscBinBCSRRegisterAll());
  grid.nx = grid.ny = grid.nz = 48;
  PetscCall(StencilGridFromOptions(nullptr, &grid));
  {
    PetscInt  nset = 17;
    PetscBool flg;
    PetscCall(PetscOptionsGetIntArray(nullptr, nullptr, "-bin_widths", widths, &nset, &flg));
    PetscCheck(nset <= 16, PETSC_COMM_WORLD, PETSC_ERR_ARG_SIZ, "-bin_widths takes at most 16 widths");
    if (flg) nw = nset;
    nset = 5;
    PetscCall(PetscOptionsGetIntArray(nullptr, nullptr, "-streams", streams, &nset, &flg));
    PetscCheck(nset <= 4, PETSC_COMM_WORLD, PETSC_ERR_ARG_SIZ,
               "-streams takes at most 4 stream counts (1,2,4,8)");
    if (flg) ns = nset;
  }
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &repeats, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-batch", &batch, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-bs", &bs, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-coo", &coo, nullptr));
  /* -bs 0 divided by zero in MatSetBlockSize, -repeats 0 printed the unset minimum (1e300) */
  PetscCheck(bs == 1 || bs == 3, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-bs must be 1 or 3, not %" PetscInt_FMT, bs);
  PetscCheck(repeats >= 1 && batch >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
             "-repeats and -batch must be >= 1 (got %" PetscInt_FMT " and %" PetscInt_FMT ")", repeats,
             batch);
  for (PetscInt i = 0; i < nw; i++)
    PetscCheck(widths[i] >= 1, PETSC_COMM_WORLD, PETSC_ERR_ARG_OUTOFRANGE,
               "-bin_widths must be >= 1, not %" PetscInt_FMT, widths[i]);
  for (PetscInt i = 0; i < ns; i++)
    PetscCheck(streams[i] == 1 || streams[i] == 2 || streams[i] == 4 || streams[i] == 8, PETSC_COMM_WORLD,
               PETSC_ERR_ARG_OUTOFRANGE, "-streams must be 1, 2, 4 or 8, not %" PetscInt_FMT, streams[i]);
  {
    char      timer[64] = "cpu";
    PetscBool flg, cpu;
    PetscCall(PetscOptionsGetString(nullptr, nullptr, "-timer", timer, sizeof timer, &flg));
    PetscCall(PetscStrcmp(timer, "wall", &use_wall));
    PetscCall(PetscStrcmp(timer, "cpu", &cpu));
    /* anything else fell back to CPU time without a word; spmv_bench refuses it too */
    PetscCheck(use_wall || cpu, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG, "-timer cpu|wall, not %s", timer);
  }

  {
    PetscBool sweep = PETSC_FALSE, files;
    PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-sweep", &sweep, nullptr));
    PetscCall(PetscOptionsHasName(nullptr, nullptr, "-f", &files));
    PetscCheck(sweep || !files, PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG,
               "binbcsr_tune: -f FILE is swept with -sweep; the table without it is for the stencil only");
    if (sweep) {
      SweepSettings s;
      char          buf[4096] = "";
      PetscBool     flg;
      s.now = Now;
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &s.repeats, nullptr));
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-batch", &s.batch, nullptr));
      PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-tune_cache", &s.tune_cache, nullptr));
      PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-sweep_verbose", &s.verbose, nullptr));
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-sweep_confirm", &s.confirm, nullptr));
      PetscCheck(s.confirm >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
                 "-sweep_confirm must be >= 0 (got %" PetscInt_FMT ")", s.confirm);
      {
        PetscInt pfs[16], npf = 16;
        PetscCall(PetscOptionsGetIntArray(nullptr, nullptr, "-sweep_prefetch", pfs, &npf, &flg));
        if (flg) s.prefetches.assign(pfs, pfs + npf);
        PetscCheck(!flg || npf > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_WRONG,
                   "-sweep_prefetch: give at least one distance");
      }
      std::vector<PetscInt> sizes;
      PetscCall(StencilSizesFromOptions(PETSC_COMM_WORLD, "binbcsr_tune -sweep", {32, 48}, 8, &sizes));
      {
        PetscBool files_given;
        PetscCall(PetscOptionsHasName(nullptr, nullptr, "-f", &files_given));
        PetscCheck(files_given || std::any_of(sizes.begin(), sizes.end(), [](PetscInt n) { return n > 0; }),
                   PETSC_COMM_WORLD, PETSC_ERR_ARG_WRONG,
                   "nothing to sweep: -stencil_sizes 0 and no -f FILE");
      }
      PetscCall(PetscPrintf(PETSC_COMM_SELF,
                            "binbcsr_tune -sweep: ms per MatMult, median of %" PetscInt_FMT
                            " rounds of %" PetscInt_FMT
                            " (%s time); best/tuned as bin width/streams; tuned/best and x baij: median"
                            " of the rounds' ratios (min: the ratio of the minima); confirmed: the"
                            " same from %" PetscInt_FMT " fresh rounds of tuned against best alone\n",
                            s.repeats, s.batch, use_wall ? "wall" : "thread CPU", s.confirm));
      for (PetscInt n : sizes) {
        if (n == 0) continue;
        StencilGrid g;
        g.nx = g.ny = g.nz = n;
        PetscCall(CreateStencilMatrix(PETSC_COMM_SELF, g, MATSEQAIJ, nullptr, &aij));
        if (bs == 1) PetscCall(MatSetBlockSize(aij, 1));
        PetscCall(TuneSweep("stencil" + std::to_string(n), aij, s));
        PetscCall(MatDestroy(&aij));
      }
      PetscCall(PetscOptionsGetString(nullptr, nullptr, "-f", buf, sizeof buf, &flg));
      std::vector<std::string> file_list;
      if (flg) PetscCall(SplitOptionList(PETSC_COMM_WORLD, "-f", buf, &file_list));
      for (const std::string &f : file_list) {
        const std::string name =
          f.substr(f.find_last_of('/') == std::string::npos ? 0 : f.find_last_of('/') + 1);
        PetscCall(LoadMatrixFile(PETSC_COMM_SELF, f, bs, &aij));
        PetscInt M, N;
        PetscCall(MatGetSize(aij, &M, &N));
        if (M == 0 || N == 0) { /* nothing to multiply: its "times" were the calls' overhead */
          PetscCall(PetscPrintf(PETSC_COMM_SELF,
                                "%-14s skipped: %" PetscInt_FMT " x %" PetscInt_FMT
                                " matrix, nothing to multiply\n",
                                name.c_str(), M, N));
          PetscCall(MatDestroy(&aij));
          continue;
        }
        PetscCall(TuneSweep(name, aij, s));
        PetscCall(MatDestroy(&aij));
      }
      PetscCall(PetscFinalize());
      return 0;
    }
  }
  PetscCall(CreateStencilMatrix(PETSC_COMM_SELF, grid, MATSEQAIJ, nullptr, &aij));
  PetscCall(CreateStencilMatrix(PETSC_COMM_SELF, grid, MATSEQBAIJ, nullptr, &baij));
  if (bs == 1) PetscCall(MatSetBlockSize(aij, 1));
  vars.push_back({"seqaij", aij});
  vars.push_back({"seqbaij", baij});
  for (PetscInt w = 0; w < nw; w++)
    for (int p = 0; p < 2; p++) {
      Mat A;
      PetscCall(MakeBinBCSR(aij, bs, widths[w], 0,
                            p ? MAT_BINBCSR_PRECISION_SINGLE : MAT_BINBCSR_PRECISION_DOUBLE, PETSC_FALSE,
                            PETSC_FALSE, &A));
      for (PetscInt k = 0; k < ns; k++) {
        Variant v;
        v.name = std::string(p ? "single" : "double") + " bw " + std::to_string(widths[w]) +
                 (ns > 1 ? " K " + std::to_string(streams[k]) : "");
        v.A       = A;
        v.streams = streams[k];
        v.owner   = k == 0;
        vars.push_back(v);
      }
    }
  PetscCall(MatCreateVecs(aij, &x, &y));
  PetscCall(VecSet(x, 1.0));
  for (PetscInt r = 0; r < repeats; r++)
    for (Variant &v : vars) {
      if (v.streams) PetscCall(MatBinBCSRSetStreams(v.A, v.streams));
      PetscCall(MatMult(v.A, x, y)); /* warm */
      const double t0 = Now();
      for (PetscInt b = 0; b < batch; b++) PetscCall(MatMult(v.A, x, y));
      v.best = PetscMin(v.best, (Now() - t0) / batch);
    }
  PetscCall(PetscPrintf(PETSC_COMM_SELF,
                        "stencil %" PetscInt_FMT "^3, bs %" PetscInt_FMT ", %" PetscInt_FMT
                        " rounds of %" PetscInt_FMT " MatMults, minimum per MatMult (%s time)\n",
                        grid.nx, bs, repeats, batch, use_wall ? "wall" : "thread CPU"));
  PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-20s %10s %8s %8s\n", "variant", "ms", "x baij", "x aij"));
  for (Variant &v : vars)
    PetscCall(PetscPrintf(PETSC_COMM_SELF, "%-20s %10.4f %8.2f %8.2f\n", v.name.c_str(), 1e3 * v.best,
                          vars[1].best / v.best, vars[0].best / v.best));
  for (Variant &v : vars)
    if (v.owner) PetscCall(MatDestroy(&v.A));
  if (coo) PetscCall(TimeCOO(grid, repeats));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&y));
  PetscCall(PetscFinalize());
  return 0;
}

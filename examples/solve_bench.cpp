// solve_bench: Krylov solvers x matrix formats on the FEM-like 27-point 3x3-block stencil, one run.
//
//   solve_bench [-stencil_n 32 | -stencil_nx/ny/nz] [-stencil_shift 1e-2]
//               [-solvers cg,cg_sr,pipecg,mcg] [-formats aij,baij,binbcsr,binbcsr_single]
//               (also binbcsr_sym, binbcsr_sym_single: -mat_binbcsr_symmetric_storage)
//               [-rtol 1e-6] [-repeats 3] [-timed_its 50] [-csv FILE]
//               [-history_csv FILE] [-history_its 200]
//
// Every solver uses PCJACOBI, the unpreconditioned residual norm, a zero initial guess and the same
// right-hand side b = A_ref x* (A_ref the double-precision aij matrix, x* a fixed smooth vector), so
// single-precision storage solves a slightly different (rounded) system for the same b.
// cg_sr is KSPCG with -ksp_cg_single_reduction.
//
// Iterations: each (solver, format) pair is solved once to -rtol (untimed: setup, first touch); the
// table reports those iterations and the final true residual ||b - A_ref x|| / ||b|| against the
// double-precision matrix.
// Timing: then the pairs are solved round-robin -repeats times for exactly -timed_its iterations
// each (convergence test off, norms still computed as in a normal solve), so that per-solve set-up
// is amortised alike and load from other processes hits all pairs alike. Time per iteration =
// KSPSolve time / iterations, min and median over the rounds, both as wall-clock time and as the
// process's CPU time. On a machine shared with other jobs the CPU time is the steadier estimate
// of the unloaded wall time (time slices lost to other processes are not counted; memory-bandwidth
// contention still is); the speedup column and the targets use CPU time, wall figures are printed.
//
// -history_csv: mcg + jacobi for exactly -history_its iterations (fixed-iteration mode: no convergence
// test) with aij double, binbcsr double and binbcsr single storage; per iteration the recursively
// updated residual and the true residual against A_ref, both relative to ||b||.
#include <petscbinbcsr.h>

#include "sim/bench_util.h"
#include "sim/stencil.h"
#include "sim/summary.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <cstdio>
#include <string>
#include <vector>

namespace {

struct Format {
  std::string label, type;
  bool        single = false;
  bool        sym    = false; // binbcsr symmetric storage
};

struct Solver {
  std::string label, type;
  bool        single_reduction = false;
};

struct Run {
  Solver              solver;
  Format              format;
  Mat                 A   = nullptr;
  KSP                 ksp = nullptr;
  std::string         note; // why the format or solver is not available
  PetscInt            its      = 0;
  KSPConvergedReason  reason   = KSP_CONVERGED_ITERATING;
  double              true_rel = -1;
  std::vector<double> per_it;     // wall seconds per iteration, one per timed round
  std::vector<double> per_it_cpu; // process CPU seconds per iteration, one per timed round
};

PetscErrorCode BuildMatrix(MPI_Comm comm, const StencilGrid &grid, const Format &f, Mat *A)
{
  PetscFunctionBegin;
  PetscCall(CreateStencilMatrix(comm, grid, f.type.c_str(), nullptr, A));
  if (f.sym) PetscCall(ReplaceWithBinBCSRSymmetric(A));
  if (f.single) {
    MatBinBCSRPrecision p;
    PetscCall(MatBinBCSRSetPrecision(*A, MAT_BINBCSR_PRECISION_SINGLE));
    PetscCall(MatBinBCSRGetPrecision(*A, &p));
    PetscCheck(p == MAT_BINBCSR_PRECISION_SINGLE, comm, PETSC_ERR_SUP, "single storage not available for %s",
               f.type.c_str());
  }
  PetscFunctionReturn(0);
}

PetscErrorCode MakeKSP(MPI_Comm comm, Mat A, const Solver &s, PetscReal rtol, PetscInt max_it, KSP *ksp)
{
  PC pc;

  PetscFunctionBegin;
  PetscCall(KSPCreate(comm, ksp));
  PetscCall(KSPSetOperators(*ksp, A, A));
  PetscCall(KSPSetType(*ksp, s.type.c_str()));
  if (s.single_reduction) PetscCall(KSPCGUseSingleReduction(*ksp, PETSC_TRUE));
  PetscCall(KSPGetPC(*ksp, &pc));
  PetscCall(PCSetType(pc, PCJACOBI));
  PetscCall(KSPSetNormType(*ksp, KSP_NORM_UNPRECONDITIONED));
  PetscCall(KSPSetTolerances(*ksp, rtol, 1e-50, PETSC_DEFAULT, max_it));
  PetscCall(KSPSetUp(*ksp));
  PetscFunctionReturn(0);
}

// ||b - A_ref x|| / ||b||
PetscErrorCode TrueRelResidual(Mat Aref, Vec b, Vec x, Vec work, double *rel)
{
  PetscReal rn, bn;

  PetscFunctionBegin;
  PetscCall(MatMult(Aref, x, work));
  PetscCall(VecAYPX(work, -1.0, b));
  PetscCall(VecNorm(work, NORM_2, &rn));
  PetscCall(VecNorm(b, NORM_2, &bn));
  *rel = rn / bn;
  PetscFunctionReturn(0);
}

double CpuTime()
{
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double Min(const std::vector<double> &v) { return v.empty() ? 0 : *std::min_element(v.begin(), v.end()); }
double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

// ---- residual history --------------------------------------------------------------------------

struct HistoryCtx {
  Mat                  Aref;
  Vec                  b, work;
  PetscReal            bnorm;
  std::vector<double> *recursive, *truth;
};

PetscErrorCode HistoryMonitor(KSP ksp, PetscInt, PetscReal rnorm, void *ctx)
{
  HistoryCtx *h = (HistoryCtx *)ctx;
  Vec         x;
  double      rel;

  PetscFunctionBegin;
  PetscCall(KSPBuildSolution(ksp, nullptr, &x));
  PetscCall(TrueRelResidual(h->Aref, h->b, x, h->work, &rel));
  h->recursive->push_back(rnorm / h->bnorm);
  h->truth->push_back(rel);
  PetscFunctionReturn(0);
}

PetscErrorCode WriteHistory(MPI_Comm comm, const StencilGrid &grid, Mat Aref, Vec b, PetscInt its,
                            const char *path)
{
  const Format formats[] = {
    {"aij", MATAIJ, false}, {"binbcsr", MATBINBCSR, false}, {"binbcsr_single", MATBINBCSR, true}};
  std::vector<std::string>         labels;
  std::vector<std::vector<double>> rec, tru;
  FILE                            *fp;

  PetscFunctionBegin;
  for (const Format &f : formats) {
    Mat                 A = nullptr;
    std::string         note;
    std::vector<double> r, t;
    PetscCall(Try(
      [&]() -> PetscErrorCode {
        KSP        ksp;
        Vec        x, work;
        HistoryCtx ctx;
        PetscFunctionBegin;
        PetscCall(BuildMatrix(comm, grid, f, &A));
        PetscCall(MakeKSP(comm, A, Solver{"mcg", KSPMCG}, 1e-30, its, &ksp));
        PetscCall(KSPMCGSetFixedIterations(ksp, its));
        PetscCall(VecDuplicate(b, &x));
        PetscCall(VecDuplicate(b, &work));
        PetscCall(VecNorm(b, NORM_2, &ctx.bnorm));
        ctx.Aref      = Aref;
        ctx.b         = b;
        ctx.work      = work;
        ctx.recursive = &r;
        ctx.truth     = &t;
        PetscCall(KSPMonitorSet(ksp, HistoryMonitor, &ctx, nullptr));
        PetscCall(KSPSolve(ksp, b, x));
        PetscCall(KSPDestroy(&ksp));
        PetscCall(VecDestroy(&x));
        PetscCall(VecDestroy(&work));
        PetscFunctionReturn(0);
      },
      &note));
    PetscCall(MatDestroy(&A));
    if (!note.empty()) {
      PetscCall(PetscPrintf(comm, "history: %s skipped (%s)\n", f.label.c_str(), note.c_str()));
      continue;
    }
    labels.push_back(f.label);
    rec.push_back(r);
    tru.push_back(t);
  }
  PetscCall(PetscFOpen(comm, path, "w", &fp));
  PetscCall(PetscFPrintf(comm, fp, "iteration"));
  for (const std::string &l : labels)
    PetscCall(PetscFPrintf(comm, fp, ",%s_recursive,%s_true", l.c_str(), l.c_str()));
  PetscCall(PetscFPrintf(comm, fp, "\n"));
  for (PetscInt k = 0; k <= its; k++) {
    PetscCall(PetscFPrintf(comm, fp, "%" PetscInt_FMT, k));
    for (size_t f = 0; f < labels.size(); f++) {
      if ((size_t)k < rec[f].size()) PetscCall(PetscFPrintf(comm, fp, ",%.6e,%.6e", rec[f][k], tru[f][k]));
      else PetscCall(PetscFPrintf(comm, fp, ",,"));
    }
    PetscCall(PetscFPrintf(comm, fp, "\n"));
  }
  PetscCall(PetscFClose(comm, fp));
  for (size_t f = 0; f < labels.size(); f++) {
    const double floor = tru[f].empty() ? 0 : *std::min_element(tru[f].begin(), tru[f].end());
    PetscCall(PetscPrintf(
      comm,
      "history %-15s: %zu iterations, lowest true residual (vs double matrix) %.2e, last recursive %.2e\n",
      labels[f].c_str(), tru[f].size() - 1, floor, rec[f].empty() ? 0.0 : rec[f].back()));
  }
  PetscCall(PetscPrintf(comm, "history written to %s\n", path));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  MPI_Comm    comm;
  StencilGrid grid;
  char        solvers_opt[256] = "cg,cg_sr,pipecg,mcg", formats_opt[256] = "aij,baij,binbcsr,binbcsr_single";
  char        csv[PETSC_MAX_PATH_LEN] = "", history_csv[PETSC_MAX_PATH_LEN] = "";
  PetscReal   rtol    = 1e-6;
  PetscInt    repeats = 3, history_its = 200, timed_its = 50;
  PetscMPIInt size;
  Mat         Aref;
  Vec         b, xstar, work;

  PetscFunctionBeginUser;
  PetscCall(PetscInitialize(&argc, &argv, nullptr, "solve_bench: Krylov solvers x matrix formats\n"));
  PetscCall(PetscBinBCSRRegisterAll());
  comm    = PETSC_COMM_WORLD;
  grid.nx = grid.ny = grid.nz = 32;
  PetscCall(StencilGridFromOptions(nullptr, &grid));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-solvers", solvers_opt, sizeof(solvers_opt), nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-formats", formats_opt, sizeof(formats_opt), nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-csv", csv, sizeof(csv), nullptr));
  PetscCall(
    PetscOptionsGetString(nullptr, nullptr, "-history_csv", history_csv, sizeof(history_csv), nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-rtol", &rtol, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &repeats, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-timed_its", &timed_its, nullptr));
  /* 0 printed NaN speed-ups, or times per iteration with no iteration behind them */
  PetscCheck(repeats >= 1 && timed_its >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-repeats and -timed_its must be >= 1 (got %" PetscInt_FMT " and %" PetscInt_FMT ")", repeats,
             timed_its);
  /* KSPSetTolerances refuses it for every pair alike: one message before the matrices are built */
  PetscCheck(rtol >= 0 && rtol < 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "-rtol must be in [0, 1), not %g",
             (double)rtol);
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-history_its", &history_its, nullptr));
  PetscCall(MPI_Comm_size(comm, &size));

  std::vector<std::string> solver_list, format_list;
  PetscCall(SplitOptionList(comm, "-solvers", solvers_opt, &solver_list));
  PetscCall(SplitOptionList(comm, "-formats", formats_opt, &format_list));
  std::vector<Solver> solvers;
  for (const std::string &s : solver_list) {
    if (s == "cg") solvers.push_back({s, KSPCG, false});
    else if (s == "cg_sr") solvers.push_back({s, KSPCG, true});
    else if (s == "pipecg") solvers.push_back({s, KSPPIPECG, false});
    else if (s == "mcg") solvers.push_back({s, KSPMCG, false});
    else SETERRQ(comm, PETSC_ERR_ARG_WRONG, "unknown solver %s (cg, cg_sr, pipecg, mcg)", s.c_str());
  }
  std::vector<Format> formats;
  for (const std::string &f : format_list) {
    if (f == "binbcsr_single") formats.push_back({f, MATBINBCSR, true});
    else if (f == "binbcsr_sym") formats.push_back({f, MATBINBCSR, false, true});
    else if (f == "binbcsr_sym_single") formats.push_back({f, MATBINBCSR, true, true});
    else formats.push_back({f, f, false});
  }

  // reference system: double-precision aij, b = A_ref x*
  PetscCall(CreateStencilMatrix(comm, grid, MATAIJ, nullptr, &Aref));
  PetscCall(MatCreateVecs(Aref, &xstar, &b));
  PetscCall(VecDuplicate(b, &work));
  {
    PetscInt lo, hi;
    PetscCall(VecGetOwnershipRange(xstar, &lo, &hi));
    for (PetscInt i = lo; i < hi; i++)
      PetscCall(VecSetValue(xstar, i, 1.0 + 0.5 * std::sin(0.001 * i), INSERT_VALUES));
    PetscCall(VecAssemblyBegin(xstar));
    PetscCall(VecAssemblyEnd(xstar));
    PetscCall(MatMult(Aref, xstar, b));
  }
  PetscInt rows;
  PetscCall(MatGetSize(Aref, &rows, nullptr));
  PetscCall(
    PetscPrintf(comm,
                "solve_bench: %" PetscInt_FMT "x%" PetscInt_FMT "x%" PetscInt_FMT " nodes, %" PetscInt_FMT
                " rows, shift %g, %d rank(s), jacobi, rtol %g (unpreconditioned norm), %" PetscInt_FMT
                " timed rounds of %" PetscInt_FMT " iterations\n",
                grid.nx, grid.ny, grid.nz, rows, (double)grid.shift, size, (double)rtol, repeats, timed_its));

  // matrices (one per format, shared by the solvers) and the untimed first solve of each pair
  std::vector<Mat>         mats(formats.size(), nullptr);
  std::vector<std::string> mat_notes(formats.size());
  for (size_t f = 0; f < formats.size(); f++)
    PetscCall(Try([&]() { return BuildMatrix(comm, grid, formats[f], &mats[f]); }, &mat_notes[f]));
  std::vector<Run> runs;
  for (const Solver &s : solvers)
    for (size_t f = 0; f < formats.size(); f++) {
      Run r;
      r.solver = s;
      r.format = formats[f];
      r.A      = mats[f];
      r.note   = mat_notes[f];
      if (r.note.empty()) {
        Vec x;
        PetscCall(VecDuplicate(b, &x));
        PetscCall(Try(
          [&]() -> PetscErrorCode {
            PetscFunctionBegin;
            PetscCall(MakeKSP(comm, r.A, s, rtol, 10000, &r.ksp));
            PetscCall(KSPSolve(r.ksp, b, x));
            PetscCall(KSPGetIterationNumber(r.ksp, &r.its));
            PetscCall(KSPGetConvergedReason(r.ksp, &r.reason));
            PetscCall(TrueRelResidual(Aref, b, x, work, &r.true_rel));
            /* timed solves: exactly timed_its iterations */
            PetscCall(KSPSetConvergenceTest(r.ksp, KSPConvergedSkip, nullptr, nullptr));
            PetscCall(KSPSetTolerances(r.ksp, PETSC_DEFAULT, PETSC_DEFAULT, PETSC_DEFAULT, timed_its));
            PetscFunctionReturn(0);
          },
          &r.note));
        PetscCall(VecDestroy(&x));
        // a solve that met Inf or NaN (an overflowing -stencil_shift) ran no iterations worth timing:
        // its speed-ups came out as NaN beside the reason. Other ends (MCG's stop at single
        // precision's floor) still time their iterations.
        if (r.note.empty() && (r.reason == KSP_DIVERGED_NANORINF || !std::isfinite(r.true_rel)))
          r.note = std::string("not timed: the solve ended ") + KSPConvergedReasons[r.reason];
        if (!r.note.empty()) PetscCall(KSPDestroy(&r.ksp));
      }
      runs.push_back(r);
    }

  // timed rounds
  Vec x;
  PetscCall(VecDuplicate(b, &x));
  for (PetscInt round = 0; round < repeats; round++)
    for (Run &r : runs) {
      if (!r.ksp) continue;
      PetscInt its;
      PetscCall(VecSet(x, 0.0));
      PetscCall(MPI_Barrier(comm));
      const double t0 = WallTime(), c0 = CpuTime();
      PetscCall(KSPSolve(r.ksp, b, x));
      const double t1 = WallTime(), c1 = CpuTime();
      PetscCall(KSPGetIterationNumber(r.ksp, &its));
      r.per_it.push_back((t1 - t0) / std::max<PetscInt>(its, 1));
      r.per_it_cpu.push_back((c1 - c0) / std::max<PetscInt>(its, 1));
    }
  PetscCall(VecDestroy(&x));

  // table
  const Run *cg_baij = nullptr, *cg_aij = nullptr;
  for (const Run &r : runs) {
    if (r.solver.label == "cg" && r.format.label == "baij" && r.ksp) cg_baij = &r;
    if (r.solver.label == "cg" && r.format.label == "aij" && r.ksp) cg_aij = &r;
  }
  const Run *base = cg_baij ? cg_baij : cg_aij;
  PetscCall(PetscPrintf(comm, "\n%-8s %-15s %5s %-16s %11s %11s %11s %11s %9s %11s\n", "solver", "format",
                        "its", "reason", "cpu ms/it", "cpu med", "wall ms/it", "wall med", "speedup",
                        "true_resid"));
  for (const Run &r : runs) {
    if (!r.ksp) {
      PetscCall(PetscPrintf(comm, "%-8s %-15s   n/a  (%s)\n", r.solver.label.c_str(), r.format.label.c_str(),
                            r.note.c_str()));
      continue;
    }
    const double speedup = base ? Min(base->per_it_cpu) / Min(r.per_it_cpu) : 0;
    PetscCall(PetscPrintf(comm,
                          "%-8s %-15s %5" PetscInt_FMT " %-16s %11.3f %11.3f %11.3f %11.3f %8.2fx %11.2e\n",
                          r.solver.label.c_str(), r.format.label.c_str(), r.its,
                          KSPConvergedReasons[r.reason], 1e3 * Min(r.per_it_cpu), 1e3 * Median(r.per_it_cpu),
                          1e3 * Min(r.per_it), 1e3 * Median(r.per_it), speedup, r.true_rel));
  }
  if (base)
    PetscCall(PetscPrintf(comm,
                          "speedup: CPU time per iteration of cg+%s divided by the row's (min over rounds)\n",
                          base->format.label.c_str()));

  // targets (one rank): mcg+binbcsr double >= 1.15x, single >= 1.8x cg+baij per iteration; iterations within 2 of cg
  SummaryLine summary;
  summary.add("bench", std::string("solve"));
  summary.add("rows", (long long)rows);
  for (const Run &r : runs) {
    if (r.solver.label != "mcg" || r.format.type != MATBINBCSR) continue;
    if (!r.ksp || !cg_baij) {
      PetscCall(
        PetscPrintf(comm, "target: mcg+%s per iteration vs cg+baij: not measured (%s has no timing, above)\n",
                    r.format.label.c_str(), !r.ksp ? ("mcg+" + r.format.label).c_str() : "cg+baij"));
      continue;
    }
    const double target              = r.format.single ? 1.8 : 1.15,
                 speedup             = Min(cg_baij->per_it_cpu) / Min(r.per_it_cpu);
    const double wall_speedup        = Min(cg_baij->per_it) / Min(r.per_it),
                 wall_median_speedup = Median(cg_baij->per_it) / Median(r.per_it);
    const Run *cg_same               = nullptr;
    for (const Run &c : runs)
      if (c.ksp && c.solver.label == "cg" && c.format.label == (r.format.single ? "baij" : r.format.label))
        cg_same = &c;
    PetscCall(PetscPrintf(
      comm,
      "target: mcg+%s per iteration vs cg+baij: %.2fx CPU (target >= %.2fx) %s [wall: %.2fx min, %.2fx median]",
      r.format.label.c_str(), speedup, target, speedup >= target ? "MET" : "NOT MET", wall_speedup,
      wall_median_speedup));
    if (cg_same)
      PetscCall(
        PetscPrintf(comm, "; iterations %" PetscInt_FMT " vs cg+%s %" PetscInt_FMT "%s", r.its,
                    cg_same->format.label.c_str(), cg_same->its,
                    r.format.single
                      ? ""
                      : (std::abs(r.its - cg_same->its) <= 2 ? " (within 2: MET)" : " (within 2: NOT MET)")));
    PetscCall(PetscPrintf(comm, "\n"));
    summary.add(std::string("speedup_mcg_") + r.format.label, speedup);
  }
  PetscCall(PrintSummary(comm, summary));

  if (csv[0]) {
    FILE *fp;
    PetscCall(PetscFOpen(comm, csv, "w", &fp));
    PetscCall(PetscFPrintf(
      comm, fp,
      "solver,format,rows,ranks,its,reason,cpu_sec_per_it_min,cpu_sec_per_it_median,wall_sec_per_it_min,wall_sec_per_it_median,true_rel_residual,note\n"));
    for (const Run &r : runs) {
      if (!r.ksp)
        PetscCall(PetscFPrintf(comm, fp, "%s,%s,%" PetscInt_FMT ",%d,,,,,,,,\"%s\"\n", r.solver.label.c_str(),
                               r.format.label.c_str(), rows, size, r.note.c_str()));
      else
        PetscCall(PetscFPrintf(
          comm, fp, "%s,%s,%" PetscInt_FMT ",%d,%" PetscInt_FMT ",%s,%.6e,%.6e,%.6e,%.6e,%.6e,\n",
          r.solver.label.c_str(), r.format.label.c_str(), rows, size, r.its, KSPConvergedReasons[r.reason],
          Min(r.per_it_cpu), Median(r.per_it_cpu), Min(r.per_it), Median(r.per_it), r.true_rel));
    }
    PetscCall(PetscFClose(comm, fp));
    PetscCall(PetscPrintf(comm, "table written to %s\n", csv));
  }
  if (history_csv[0]) PetscCall(WriteHistory(comm, grid, Aref, b, history_its, history_csv));

  for (Run &r : runs) PetscCall(KSPDestroy(&r.ksp));
  for (Mat &A : mats) PetscCall(MatDestroy(&A));
  PetscCall(MatDestroy(&Aref));
  PetscCall(VecDestroy(&b));
  PetscCall(VecDestroy(&xstar));
  PetscCall(VecDestroy(&work));
  PetscCall(PetscFinalize());
  return 0;
}

// spmv_bench: MatMult timed for PETSc's built-in formats and MATBINBCSR (double and single storage) on
// the same matrices in the same run, against a STREAM-triad bandwidth measured in the same run.
//
//   spmv_bench [-stencil_sizes 16,32,48 | -stencil_n N] [-f FILE]...
//              [-formats aij,baij,sbaij,sell,binbcsr,binbcsr_single,binbcsr_sym,binbcsr_sym_single]
//              [-repeats 7] [-min_batch_ms 20] [-csv FILE] [-stats_only] [-stream_elements N]
//              [-save_dir DIR] (also write each stencil matrix to DIR/stencilN.bin, PETSc binary)
//              [-timer wall|cpu] (cpu: process CPU time, for a machine shared with other work)
//
// Matrices: the 27-point 3x3-block stencil (src/sim/stencil.h) on an n^3 node grid for each n of
// -stencil_sizes (0 = none; or the one n of -stencil_n), and every PETSc binary file given with -f
// (repeatable, or a comma list; the block size comes from the file's .info, -matload_block_size, or -bs).
// Under mpiexec the same types are used in their mpi forms (rows split by PETSc's default layout).
//
// Timing: the formats are timed round-robin (one batch of MatMults per format per round, -repeats
// rounds) so that load from other processes hits them alike; a batch is long enough to last
// -min_batch_ms. Per MatMult: min and median over the rounds. Each round also runs one STREAM triad
// pass and one pass of the best read pattern (sim/read_bw.h: one array read as 1, 2, 4, 8
// interleaved streams and with AVX-512 / AVX2 sums, measured at the start). %read is relative to the
// best read bandwidth of all those passes: the physical limit of a product that reads its matrix
// once. %triad is relative to the best triad pass (two reads and a write: not that limit).
// GFlop/s = 2 nnz / t with nnz the nonzeros of the full matrix (also for sbaij, which stores half).
// Bytes model (GB/s): the matrix's stored arrays read once (values, column indices, row or bin
// offsets, padding included) + x read once + y written once; per format in src/sim/format_bytes.h.
// Padding overhead of binbcsr = slots / blocks - 1 (upper blocks for symmetric storage).
#include <petscbinbcsr.h>

#include "sim/bench_util.h"
#include "sim/format_bytes.h"
#include "sim/matrix_file.h"
#include "sim/stencil.h"
#include "sim/read_bw.h"
#include "sim/stream.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace {

struct FormatSpec {
  std::string label; // column in the table: aij, baij, ..., binbcsr_single
  std::string type;  // the MatType root name
  bool        single = false;
  bool        sym    = false; // binbcsr symmetric storage (upper triangle)
};

// Where a matrix comes from: a stencil grid or a binary file.
struct MatrixSource {
  std::string name;
  bool        is_file = false;
  StencilGrid grid;
  std::string path;
};

struct Candidate {
  FormatSpec          spec;
  Mat                 A = nullptr;
  std::string         actual_type, note;
  PetscInt            inner = 1;
  std::vector<double> per_mult; // seconds per MatMult, one per round
  double              bytes = 0, padding = -1, padding_info = -1, rel_err = 0;
  PetscInt            bin_width = 0;
};

double ModelBytes(const Candidate &c, const MatrixStats &st, MPI_Comm comm, double *padding)
{
  return FormatModelBytes(c.spec.type, c.spec.single, c.spec.sym, c.bin_width, c.A, st, comm, padding);
}

PetscErrorCode BuildCandidate(MPI_Comm comm, const MatrixSource &src, Mat aij_file, Candidate *c)
{
  PetscFunctionBegin;
  if (src.is_file) {
    if (c->spec.type == "aij") PetscCall(MatDuplicate(aij_file, MAT_COPY_VALUES, &c->A));
    else PetscCall(MatConvert(aij_file, c->spec.type.c_str(), MAT_INITIAL_MATRIX, &c->A));
  } else {
    PetscCall(CreateStencilMatrix(comm, src.grid, c->spec.type.c_str(), nullptr, &c->A));
  }
  /* the same entries, upper triangle kept for _sym; single storage set before the layout build, as a
     driver's -mat_binbcsr_precision is, so that the tuner chooses for single */
  if (c->spec.sym || c->spec.single)
    PetscCall(
      ReplaceWithBinBCSR(&c->A, c->spec.sym ? PETSC_TRUE : PETSC_FALSE,
                         c->spec.single ? MAT_BINBCSR_PRECISION_SINGLE : MAT_BINBCSR_PRECISION_DOUBLE));
  if (c->spec.single) {
    MatBinBCSRPrecision p;
    PetscCall(MatBinBCSRGetPrecision(c->A, &p));
    PetscCheck(p == MAT_BINBCSR_PRECISION_SINGLE, comm, PETSC_ERR_SUP, "single storage not available");
  }
  if (c->spec.type == "binbcsr") PetscCall(MatBinBCSRGetBinWidth(c->A, &c->bin_width));
  MatType t;
  PetscCall(MatGetType(c->A, &t));
  c->actual_type = t;
  PetscFunctionReturn(0);
}

double Median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

double Min(const std::vector<double> &v) { return v.empty() ? 0 : *std::min_element(v.begin(), v.end()); }

struct Settings {
  std::vector<FormatSpec> formats;
  PetscInt                repeats      = 7;
  PetscReal               min_batch_ms = 20;
  PetscBool               stats_only   = PETSC_FALSE;
  FILE                   *csv          = nullptr;
  TriadArrays            *triad        = nullptr; // one triad pass per round, beside the MatMults
  ReadArray              *read         = nullptr; // one pass of the best read pattern per round
  PetscInt                file_bs      = 0;
  std::string             save_dir; // -save_dir: write each stencil matrix (aij) as a PETSc binary file
  PetscBool               cpu_clock = PETSC_FALSE; // -timer cpu: process CPU time instead of wall time
};

double Clock(const Settings &set) { return set.cpu_clock ? ProcessCpuSeconds() : MPI_Wtime(); }

PetscErrorCode BenchMatrix(MPI_Comm comm, const MatrixSource &src, const Settings &set)
{
  Mat         aij_file = nullptr, reference = nullptr;
  MatrixStats st;

  PetscFunctionBegin;
  if (src.is_file) {
    PetscCall(LoadMatrixFile(comm, src.path, set.file_bs, &aij_file));
    // Assembled FE matrices are symmetric only up to the rounding of their sums: tolerance relative
    // to the largest entry.
    PetscBool symmetric = PETSC_FALSE;
    PetscReal amax;
    PetscCall(MatNorm(aij_file, NORM_MAX, &amax));
    PetscCall(MatIsSymmetric(aij_file, 1e-12 * amax, &symmetric));
    if (symmetric) PetscCall(MatSetOption(aij_file, MAT_SYMMETRIC, PETSC_TRUE));
    reference = aij_file;
  } else {
    PetscCall(CreateStencilMatrix(comm, src.grid, MATAIJ, nullptr, &reference));
    if (!set.save_dir.empty()) {
      const std::string path = set.save_dir + "/" + src.name + ".bin";
      PetscViewer       viewer;
      PetscCall(PetscViewerBinaryOpen(comm, path.c_str(), FILE_MODE_WRITE, &viewer));
      PetscCall(MatView(reference, viewer)); // the .info file next to it records the block size
      PetscCall(PetscViewerDestroy(&viewer));
      PetscCall(PetscPrintf(comm, "wrote %s\n", path.c_str()));
    }
  }
  { /* a 0 x 0 (or M x 0) file has no product to time: every format printed a NaN error, the CSV a
       minimum row length of PETSC_MAX_INT and a NaN average */
    PetscInt M, N;
    PetscCall(MatGetSize(reference, &M, &N));
    if (M == 0 || N == 0) {
      PetscCall(PetscPrintf(
        comm, "\n== %s: %" PetscInt_FMT " x %" PetscInt_FMT " matrix, nothing to multiply: skipped\n",
        src.name.c_str(), M, N));
      if (set.csv)
        for (const FormatSpec &f : set.formats)
          PetscCall(PetscFPrintf(comm, set.csv, "%s,%s,%" PetscInt_FMT ",0,,,,,,,,,,,,,,,,,,,,,skipped\n",
                                 src.name.c_str(), f.label.c_str(), M));
      PetscCall(MatDestroy(&reference));
      PetscFunctionReturn(0);
    }
  }
  PetscCall(MeasureStats(reference, &st));

  std::vector<Candidate> cands;
  for (const FormatSpec &f : set.formats) {
    Candidate c;
    c.spec = f;
    if (f.type == "sbaij" && src.is_file) {
      PetscBool known = PETSC_FALSE, sym = PETSC_FALSE;
      PetscCall(MatIsSymmetricKnown(aij_file, &known, &sym));
      if (!known || !sym) c.note = "matrix not symmetric";
    }
    if (c.note.empty()) PetscCall(Try([&] { return BuildCandidate(comm, src, aij_file, &c); }, &c.note));
    if (!c.note.empty() && c.A) {
      PetscCall(PetscPushErrorHandler(PetscReturnErrorHandler, nullptr));
      (void)MatDestroy(&c.A);
      PetscCall(PetscPopErrorHandler());
      c.A = nullptr;
    }
    cands.push_back(c);
  }

  // Reference product (aij, double) and a first product of each format: correctness, warm-up, and
  // how many products make one batch.
  Vec x, y_ref, y;
  PetscCall(MatCreateVecs(reference, &x, &y_ref));
  PetscCall(VecDuplicate(y_ref, &y));
  {
    PetscInt     lo, hi;
    PetscScalar *xa;
    PetscCall(VecGetOwnershipRange(x, &lo, &hi));
    PetscCall(VecGetArray(x, &xa));
    for (PetscInt i = lo; i < hi; ++i) xa[i - lo] = 1.0 + 0.5 * std::sin(0.1 * (double)i);
    PetscCall(VecRestoreArray(x, &xa));
  }
  PetscCall(MatMult(reference, x, y_ref));
  PetscReal ref_norm;
  PetscCall(VecNorm(y_ref, NORM_INFINITY, &ref_norm));

  for (Candidate &c : cands) {
    if (!c.A) continue;
    c.bytes = ModelBytes(c, st, comm, &c.padding);
    if (c.spec.type == "binbcsr") {
      // The matrix's own count, when it answers MatGetInfo (a cross-check of the model; optional).
      MatInfo     info;
      std::string ignored;
      info.nz_allocated = info.nz_used = 0;
      PetscCall(Try([&] { return MatGetInfo(c.A, MAT_GLOBAL_SUM, &info); }, &ignored));
      if (ignored.empty() && info.nz_allocated > 0 && info.nz_used > 0)
        c.padding_info = 100.0 * (info.nz_allocated - info.nz_used) / info.nz_used;
    }
    if (set.stats_only) continue;
    PetscCall(Try(
      [&]() -> PetscErrorCode {
        PetscCall(MatMult(c.A, x, y));
        PetscCall(MatMult(c.A, x, y));
        PetscCall(VecAXPY(y, -1.0, y_ref));
        PetscReal d;
        PetscCall(VecNorm(y, NORM_INFINITY, &d));
        c.rel_err = ref_norm > 0 ? d / ref_norm : d; /* a zero matrix: the absolute difference */
        PetscCallMPI(MPI_Barrier(comm));
        double t0 = Clock(set);
        PetscCall(MatMult(c.A, x, y));
        double t = Clock(set) - t0;
        PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, comm));
        /* in double, clamped before the cast: a long -min_batch_ms over a fast product passed PETSC_MAX_INT */
        c.inner =
          (PetscInt)std::min(1e9, std::max(1.0, std::ceil(set.min_batch_ms * 1e-3 / std::max(t, 1e-9))));
        return 0;
      },
      &c.note));
  }

  std::vector<double> triad_seconds;
  for (PetscInt round = 0; round < (set.stats_only ? 0 : set.repeats); ++round) {
    if (set.triad) {
      double t;
      PetscCall(TriadArraysRun(comm, set.triad, &t));
      triad_seconds.push_back(t);
    }
    if (set.read) {
      double g;
      PetscCall(ReadArrayRun(comm, set.read, ReadArrayBest(set.read), &g));
    }
    for (Candidate &c : cands) {
      if (!c.A || !c.note.empty()) continue;
      PetscCallMPI(MPI_Barrier(comm));
      const double t0 = Clock(set);
      for (PetscInt k = 0; k < c.inner; ++k) PetscCall(MatMult(c.A, x, y));
      double t = (Clock(set) - t0) / (double)c.inner;
      PetscCallMPI(MPI_Allreduce(MPI_IN_PLACE, &t, 1, MPI_DOUBLE, MPI_MAX, comm));
      c.per_mult.push_back(t);
    }
  }

  // Report.
  PetscMPIInt size;
  PetscCallMPI(MPI_Comm_size(comm, &size));
  PetscCall(PetscPrintf(comm,
                        "\n== %s: %" PetscInt_FMT " rows, nnz %.0f, bs %" PetscInt_FMT
                        ", row length max %" PetscInt_FMT " min %" PetscInt_FMT " avg %.1f, %d rank(s)\n",
                        src.name.c_str(), st.rows, st.nnz, st.bs, st.max_row, st.min_row, st.avg_row, size));
  {
    double       aij_bytes = 12.0 * st.nnz;
    const double resident  = (double)ResidentCacheBytes(); // measured: a VM's claim may be its host's
    if (resident > 0 && aij_bytes < 2 * resident)
      PetscCall(PetscPrintf(
        comm,
        "   (aij values+indices %.0f MB vs %.0f MB that stay in the caches: partly cache-resident, %%read and %%triad may exceed 100)\n",
        aij_bytes * 1e-6, resident * 1e-6));
  }
  const double triad_GBs =
    (set.triad && !triad_seconds.empty()) ? set.triad->bytes / Min(triad_seconds) * 1e-9 : 0;
  if (triad_GBs > 0)
    PetscCall(PetscPrintf(comm, "   STREAM triad in the same rounds: %.2f GB/s (best of %d)\n", triad_GBs,
                          (int)triad_seconds.size()));
  const double read_GBs = set.read ? set.read->patterns[ReadArrayBest(set.read)].best_GBs : 0;
  if (read_GBs > 0)
    PetscCall(PetscPrintf(comm, "   read bandwidth (best pattern, %s, so far): %.2f GB/s\n",
                          set.read->patterns[ReadArrayBest(set.read)].name.c_str(), read_GBs));
  double t_aij = 0, t_baij = 0, b_baij = 0;
  for (const Candidate &c : cands) {
    if (c.spec.label == "aij" && !c.per_mult.empty()) t_aij = Min(c.per_mult);
    if (c.spec.label == "baij" && !c.per_mult.empty()) t_baij = Min(c.per_mult);
    if (c.spec.label == "baij" && c.A) b_baij = c.bytes;
  }
  PetscCall(PetscPrintf(comm, "%-15s %-11s %9s %9s %8s %8s %7s %7s %9s %7s %7s %7s %7s %9s\n", "format",
                        "type", "ms(min)", "ms(med)", "GFlop/s", "GB/s", "%read", "%triad", "MB", "/baijB",
                        "x aij", "x baij", "pad%", "rel.err"));
  for (const Candidate &c : cands) {
    if (!c.A || !c.note.empty()) {
      PetscCall(PetscPrintf(comm, "%-15s skipped: %s\n", c.spec.label.c_str(),
                            c.note.empty() ? "not created" : c.note.c_str()));
      if (set.csv)
        PetscCall(PetscFPrintf(comm, set.csv,
                               "%s,%s,%" PetscInt_FMT ",%.0f,%" PetscInt_FMT ",%" PetscInt_FMT
                               ",%" PetscInt_FMT ",%.2f,%d,,,,,,,,,,,,,%.3f,,%.3f,skipped\n",
                               src.name.c_str(), c.spec.label.c_str(), st.rows, st.nnz, st.bs, st.max_row,
                               st.min_row, st.avg_row, size, triad_GBs, read_GBs));
      continue;
    }
    const double tmin = Min(c.per_mult), tmed = Median(c.per_mult);
    const double gflops = tmin > 0 ? 2.0 * st.nnz / tmin * 1e-9 : 0,
                 gbs    = tmin > 0 ? c.bytes / tmin * 1e-9 : 0;
    const double frac   = triad_GBs > 0 ? 100.0 * gbs / triad_GBs : 0,
                 rfrac  = read_GBs > 0 ? 100.0 * gbs / read_GBs : 0;
    char pad[32] = "-", xa[16] = "-", xb[16] = "-", rb[16] = "-";
    if (c.padding >= 0) std::snprintf(pad, sizeof pad, "%.1f", c.padding);
    if (t_aij > 0 && tmin > 0) std::snprintf(xa, sizeof xa, "%.2f", t_aij / tmin);
    if (t_baij > 0 && tmin > 0) std::snprintf(xb, sizeof xb, "%.2f", t_baij / tmin);
    if (b_baij > 0) std::snprintf(rb, sizeof rb, "%.2f", c.bytes / b_baij);
    PetscCall(PetscPrintf(comm,
                          "%-15s %-11s %9.4f %9.4f %8.2f %8.2f %7.1f %7.1f %9.1f %7s %7s %7s %7s %9.1e\n",
                          c.spec.label.c_str(), c.actual_type.c_str(), tmin * 1e3, tmed * 1e3, gflops, gbs,
                          rfrac, frac, c.bytes * 1e-6, rb, xa, xb, pad, c.rel_err));
    if (set.csv)
      PetscCall(PetscFPrintf(comm, set.csv,
                             "%s,%s,%" PetscInt_FMT ",%.0f,%" PetscInt_FMT ",%" PetscInt_FMT ",%" PetscInt_FMT
                             ",%.2f,%d,%s,%.6f,%.6f,%.4f,%.4f,%.2f,%.0f,%s,%s,%s,%s,%.3e,%.3f,%.2f,%.3f,ok\n",
                             src.name.c_str(), c.spec.label.c_str(), st.rows, st.nnz, st.bs, st.max_row,
                             st.min_row, st.avg_row, size, c.actual_type.c_str(), tmin * 1e3, tmed * 1e3,
                             gflops, gbs, frac, c.bytes, rb, xa, xb, c.padding >= 0 ? pad : "", c.rel_err,
                             triad_GBs, rfrac, read_GBs));
    if (c.spec.label == "binbcsr")
      PetscCall(PetscPrintf(
        comm, "  (binbcsr bin width %" PetscInt_FMT " block rows; -mat_binbcsr_bin_width changes it)\n",
        c.bin_width));
    if (c.padding >= 0 && c.padding_info >= 0 && std::fabs(c.padding - c.padding_info) > 0.5)
      PetscCall(PetscPrintf(comm,
                            "  note: %s reports %.1f%% padding through MatGetInfo (model above: %.1f%%)\n",
                            c.spec.label.c_str(), c.padding_info, c.padding));
  }

  for (Candidate &c : cands) PetscCall(MatDestroy(&c.A));
  PetscCall(VecDestroy(&x));
  PetscCall(VecDestroy(&y));
  PetscCall(VecDestroy(&y_ref));
  PetscCall(MatDestroy(&reference));
  PetscFunctionReturn(0);
}

} // namespace

int main(int argc, char **argv)
{
  // -f may be repeated: PETSc's options database keeps only the last one, so collect them first.
  std::vector<std::string> files;
  std::string              empty_f; // the value of a -f that lists no file ("," or none): refused below
  bool                     has_empty_f = false;
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "-f")) {
      const std::string              value = i + 1 < argc ? argv[i + 1] : "";
      const std::vector<std::string> list  = SplitList(value);
      if (list.empty() && !has_empty_f) {
        empty_f     = value;
        has_empty_f = true;
      }
      files.insert(files.end(), list.begin(), list.end());
    }

  PetscCall(PetscInitialize(&argc, &argv, nullptr, "MatMult benchmark: PETSc formats and MATBINBCSR.\n"));
  PetscCall(PetscBinBCSRRegisterAll());
  MPI_Comm comm = PETSC_COMM_WORLD;
  if (has_empty_f) { // refused with SplitOptionList's words, as every other list
    std::vector<std::string> none;
    PetscCall(SplitOptionList(comm, "-f", empty_f, &none));
  }

  Settings  set;
  char      buf[PETSC_MAX_PATH_LEN] = "";
  PetscBool flg;
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-formats", buf, sizeof buf, &flg));
  const std::string formats =
    flg ? buf : "aij,baij,sbaij,sell,binbcsr,binbcsr_single,binbcsr_sym,binbcsr_sym_single";
  std::vector<std::string> format_list;
  PetscCall(SplitOptionList(comm, "-formats", formats, &format_list));
  for (const std::string &f : format_list) {
    FormatSpec spec;
    spec.label = f;
    spec.type  = f;
    if (f == "binbcsr_single" || f == "binbcsr_sym" || f == "binbcsr_sym_single") {
      spec.type   = "binbcsr";
      spec.single = f != "binbcsr_sym";
      spec.sym    = f != "binbcsr_single";
    }
    PetscCheck(
      spec.type == "aij" || spec.type == "baij" || spec.type == "sbaij" || spec.type == "sell" ||
        spec.type == "binbcsr",
      comm, PETSC_ERR_ARG_WRONG,
      "Unknown format %s: use aij, baij, sbaij, sell, binbcsr, binbcsr_single, binbcsr_sym, binbcsr_sym_single",
      f.c_str());
    set.formats.push_back(spec);
  }
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-repeats", &set.repeats, nullptr));
  PetscCall(PetscOptionsGetReal(nullptr, nullptr, "-min_batch_ms", &set.min_batch_ms, nullptr));
  PetscCall(PetscOptionsGetBool(nullptr, nullptr, "-stats_only", &set.stats_only, nullptr));
  PetscCall(PetscOptionsGetInt(nullptr, nullptr, "-bs", &set.file_bs, nullptr));
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-timer", buf, sizeof buf, &flg));
  if (flg) {
    PetscCheck(!std::strcmp(buf, "wall") || !std::strcmp(buf, "cpu"), comm, PETSC_ERR_ARG_WRONG,
               "-timer wall|cpu, not %s", buf);
    set.cpu_clock = (PetscBool)!std::strcmp(buf, "cpu");
  }
  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-save_dir", buf, sizeof buf, &flg));
  if (flg) set.save_dir = buf;
  PetscCheck(set.repeats > 0, comm, PETSC_ERR_ARG_OUTOFRANGE, "-repeats must be positive");
  /* a NaN -min_batch_ms made the batch size NaN (cast to an integer: undefined), 0 and negatives
     timed single products */
  PetscCheck(set.min_batch_ms > 0 && std::isfinite((double)set.min_batch_ms), comm, PETSC_ERR_ARG_OUTOFRANGE,
             "-min_batch_ms must be positive and finite, not %g", (double)set.min_batch_ms);
  { /* read by MeasureStreamTriadFromOptions, where 0 and negatives silently meant the default */
    PetscInt  v;
    PetscBool given;
    for (const char *name : {"-stream_elements", "-stream_repeats"}) {
      PetscCall(PetscOptionsGetInt(nullptr, nullptr, name, &v, &given));
      PetscCheck(!given || v >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE, "%s must be >= 1, not %" PetscInt_FMT,
                 name, v);
    }
  }
  { /* -bs: the files' block size, or not given (0: the file's own); 0 and negatives were taken silently */
    PetscBool bs_set;
    PetscCall(PetscOptionsHasName(nullptr, nullptr, "-bs", &bs_set));
    PetscCheck(!bs_set || set.file_bs >= 1, comm, PETSC_ERR_ARG_OUTOFRANGE,
               "-bs must be >= 1, not %" PetscInt_FMT, set.file_bs);
  }

  std::vector<MatrixSource> sources;
  std::vector<PetscInt>     sizes;
  PetscCall(StencilSizesFromOptions(comm, "spmv_bench", {16, 32, 48}, 16, &sizes));
  for (PetscInt n : sizes) {
    if (n == 0) continue;
    MatrixSource s;
    s.grid.nx = s.grid.ny = s.grid.nz = n;
    s.name                            = "stencil" + std::to_string(n);
    sources.push_back(s);
  }
  // -stencil_sizes 0 and no -f: nothing to time, and the run exited 0 as if it had measured
  PetscCheck(!sources.empty() || !files.empty(), comm, PETSC_ERR_ARG_WRONG,
             "nothing to measure: -stencil_sizes 0 and no -f FILE");
  for (const std::string &p : files) {
    MatrixSource s;
    s.is_file = true;
    s.path    = p;
    s.name    = p.substr(p.find_last_of('/') == std::string::npos ? 0 : p.find_last_of('/') + 1);
    sources.push_back(s);
  }

  PetscCall(PetscOptionsGetString(nullptr, nullptr, "-csv", buf, sizeof buf, &flg));
  if (flg) {
    PetscCall(PetscFOpen(comm, buf, "w", &set.csv));
    PetscCall(PetscFPrintf(
      comm, set.csv,
      "matrix,format,rows,nnz,bs,max_row,min_row,avg_row,ranks,type,ms_min,ms_median,gflops,gbs,pct_triad,bytes,bytes_vs_baij,speedup_vs_aij,speedup_vs_baij,padding_pct,rel_err,triad_gbs,pct_read,read_gbs,status\n"));
  }

  StreamResult stream;
  TriadArrays  triad;
  ReadArray    read;
  if (!set.stats_only) {
    PetscCall(MeasureStreamTriadFromOptions(comm, &stream));
    PetscCall(TriadArraysCreate(comm, stream.elements_per_rank, &triad));
    triad.cpu_clock = set.cpu_clock;
    set.triad       = &triad;
    PetscCall(ReadArrayCreate(comm, 0, &read));
    read.cpu_clock = set.cpu_clock;
    PetscCall(ReadArrayMeasureAll(comm, &read, 5));
    set.read = &read;
    PetscCall(PetscPrintf(
      comm, "Read bandwidth of one %.0f MB array per rank (%d rank(s), best of 5 passes each, GB/s):",
      8e-6 * (double)read.n, stream.ranks));
    for (const ReadPattern &rp : read.patterns)
      PetscCall(PetscPrintf(comm, "  %s %.2f", rp.name.c_str(), rp.best_GBs));
    PetscCall(PetscPrintf(
      comm,
      "\n  %%read: a format's bytes-model GB/s against the best of these (also passes beside the products); %%triad: against STREAM triad\n"));
    if (LastLevelCacheBytes() > 0) {
      const size_t resident = ResidentCacheBytes();
      PetscCall(
        PetscPrintf(comm,
                    "Last-level cache %.1f MiB (/sys/devices/system/cpu/cpu0/cache); measured: arrays "
                    "of up to %.0f MiB stay in the caches from one read pass to the next\n",
                    (double)LastLevelCacheBytes() / (1 << 20), (double)resident / (1 << 20)));
    }
    PetscCall(PetscPrintf(
      comm,
      "STREAM triad: %.2f GB/s best, %.2f GB/s median (%d rank(s), %.0f MB per array in all, %" PetscInt_FMT
      " repeats)\n",
      stream.best_GBs, stream.median_GBs, stream.ranks,
      8e-6 * (double)stream.elements_per_rank * stream.ranks, stream.repeats));
  }
  PetscCall(PetscPrintf(
    comm,
    "Bytes model: stored matrix arrays (padding included) + x + y, each once; GFlop/s = 2 nnz / t; ms per MatMult (%s)\n",
    set.cpu_clock ? "process CPU time: -timer cpu" : "wall clock"));
  for (const MatrixSource &s : sources) PetscCall(BenchMatrix(comm, s, set));
  if (set.csv) PetscCall(PetscFClose(comm, set.csv));
  if (set.triad) PetscCall(TriadArraysDestroy(set.triad));
  if (set.read) PetscCall(ReadArrayDestroy(set.read));
  PetscCall(PetscFinalize());
  return 0;
}

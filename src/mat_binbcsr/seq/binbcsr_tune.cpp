/* MATSEQBINBCSR: the per-machine tuning of the bin width and the stream count (-mat_binbcsr_tune).

   It runs where a layout is built from a final pattern (MatSeqBinBCSRBuildLayout: first final
   assembly, COO preallocation, conversion, load), before the layout exists, so the matrix is built
   once, with the chosen width: no second copy of the values, and the COO maps, the colouring of
   symmetric storage and the parts of an MPI matrix only ever see the final layout. The timing needs
   only the pattern: products of a sample (a slab of consecutive block rows, about twice the
   last-level cache, or the whole matrix when smaller) with the candidate layouts, values set to a
   constant (the time of a product does not depend on them). A matrix larger than the last-level cache
   is read from memory by every product, so the sample is too: its arrays are dropped from the caches
   before each timed product.

   Candidates, in the order the budget (about 30 products or 50 ms of products) admits them:
   streams 1, 2, 4, 8 at the default width; the other widths (4, 8, 16, and 32 for bs 1) at the best
   stream count; then the other stream counts at the best width. A width or stream count set
   explicitly (option or MatBinBCSRSet*) is kept and only the other parameter is tuned. Last, the
   other kernel body sets the CPU has (kernels/binbcsr_dispatch.h) at the best width and streams,
   unless -mat_binbcsr_kernel / MatBinBCSRSetKernel chose one. Products are timed in this thread's
   CPU time (the budget too); the cost reported is wall time. */
#include "binbcsr.h"
#include "../common/binbcsr_tune.h"
#include "../common/binbcsr_machine.h"
#include <petsctime.h>
#include <algorithm>
#include <cmath>
#include <ctime>
#include <vector>

namespace {

constexpr double   budget_seconds  = 0.050;
constexpr PetscInt budget_products = 30;
constexpr PetscInt min_tune_kib =
  512; /* smaller matrices live in L2: any layout does (-mat_binbcsr_tune_min_kib) */

/* The matrix class of a cache key: block size, precision, storage, size bucket (log2 of the value
   bytes), mean row length bucket (log2) and row-length spread (coefficient of variation in quarters),
   plus the parameters set explicitly (their values are part of the question). */
std::string MatrixClass(const Mat_SeqBinBCSR *a, size_t vbytes, double mean, double cv, PetscBool bw_fixed,
                        PetscBool k_fixed, PetscBool body_fixed)
{
  std::string c = "bs " + std::to_string(a->bs) + " " +
                  (a->precision == MAT_BINBCSR_PRECISION_SINGLE ? "single" : "double") +
                  (a->sym ? " symmetric" : " whole");
  c += " size 2^" + std::to_string((int)std::lround(std::log2((double)std::max<size_t>(vbytes, 1))));
  c += " rowlen 2^" + std::to_string((int)std::lround(std::log2(std::max(mean, 1.0))));
  c += " spread " + std::to_string(std::min(16, (int)(cv * 4.0)));
  if (bw_fixed) c += " bw=" + std::to_string(a->bw);
  if (k_fixed) c += " streams=" + std::to_string(a->streams);
  if (body_fixed) c += std::string(" kernel=") + MatBinBCSRKernels[a->kernel];
  return c;
}

struct Sample {
  PetscInt              nr = 0, nc = 0; /* block rows and block columns of the slab */
  std::vector<PetscInt> bi, bj;
};

/* Rows [r0, r0 + nr) of the pattern; symmetric storage keeps the principal block (square, as its
   product needs), whole storage all columns. */
Sample Slab(const Mat_SeqBinBCSR *a, const PetscInt bi[], const PetscInt bj[], PetscInt r0, PetscInt nr)
{
  Sample s;
  s.nr = nr;
  s.nc = a->sym ? nr : a->nbs;
  s.bi.push_back(0);
  for (PetscInt r = r0; r < r0 + nr; r++) {
    for (PetscInt p = bi[r]; p < bi[r + 1]; p++) {
      if (!a->sym) s.bj.push_back(bj[p]);
      else if (bj[p] >= r && bj[p] < r0 + nr) s.bj.push_back(bj[p] - r0);
    }
    s.bi.push_back((PetscInt)s.bj.size());
  }
  return s;
}

/* A MATSEQBINBCSR over the sample with bin width bw, A's precision and storage, tuning off, values a
   constant (every page written, so the products read memory, not the shared zero page). */
PetscErrorCode SampleMatrix(const Mat_SeqBinBCSR *a, const Sample &s, PetscInt bw, Mat *T)
{
  Mat_SeqBinBCSR *t;

  PetscFunctionBegin;
  PetscCall(MatCreate(PETSC_COMM_SELF, T));
  PetscCall(MatSetSizes(*T, s.nr * a->bs, s.nc * a->bs, s.nr * a->bs, s.nc * a->bs));
  PetscCall(MatSetBlockSize(*T, a->bs));
  PetscCall(MatSetType(*T, MATSEQBINBCSR));
  t            = (Mat_SeqBinBCSR *)(*T)->data;
  t->tune      = 0;
  t->bw        = bw;
  t->bw_set    = PETSC_TRUE;
  t->precision = a->precision;
  t->sym       = a->sym;
  t->kernel    = a->kernel; /* a set chosen explicitly is the one timed */
  PetscCall(MatSeqBinBCSRBuildLayout(*T, s.bi.data(), s.bj.data()));
  if (t->val) std::fill(t->val, t->val + (size_t)t->nslots * t->bs2, (MatScalar)1e-3);
  else std::fill(t->valf, t->valf + (size_t)t->nslots * t->bs2, 1e-3f);
  PetscCall(MatAssemblyBegin(*T, MAT_FINAL_ASSEMBLY));
  PetscCall(MatAssemblyEnd(*T, MAT_FINAL_ASSEMBLY));
  PetscFunctionReturn(0);
}

struct Timer {
  Vec      x = nullptr, y = nullptr;
  PetscInt products = 0;
  double   seconds  = 0;     /* time in timed products */
  bool     cold     = false; /* the sample's arrays dropped from the caches before each product */

  /* CPU seconds of this thread: on a machine shared with other work the wall clock also counts the
     time the process waits for a core, which would decide the choice by chance */
  static double Now()
  {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
  }
  /* Seconds of one product of T with K streams (the product op itself: no log events, no checks). */
  PetscErrorCode Time(Mat T, PetscInt K, double *sec)
  {
    Mat_SeqBinBCSR *t = (Mat_SeqBinBCSR *)T->data;

    PetscFunctionBegin;
    t->streams = K;
    /* A matrix larger than the last-level cache streams from memory at every product; a sample of
       about twice that cache still partly stays in it from one timed product to the next (a victim
       L3 keeps part of what a pass evicts), and then rewards the bodies that compute fastest rather
       than the ones that keep the memory busy: on a Zen 4 core the sample ranked bin width 8 first
       and the whole 48^3 stencil ran 1.4x slower with it than with width 4. */
    if (cold) {
      binbcsr::evict_from_caches(t->val ? (const void *)t->val : (const void *)t->valf,
                                 (size_t)t->nslots * t->bs2 * (t->val ? sizeof(MatScalar) : sizeof(float)));
      binbcsr::evict_from_caches(t->col, (size_t)t->nslots * sizeof(PetscInt));
    }
    const double t0 = Now();
    PetscCall(MatMult_SeqBinBCSR(T, x, y));
    *sec = Now() - t0;
    products++;
    seconds += *sec;
    PetscFunctionReturn(0);
  }
  bool Admits(PetscInt n, double per) const
  {
    return products + n <= budget_products && seconds + n * per <= budget_seconds;
  }
};

struct Tried {
  PetscInt bw, K;
  double   sec;
  PetscInt kernel; /* MatBinBCSRKernel; AUTO: the dispatch's default body */
};

} // namespace

/* Resolves the tune and cache settings: the value set, else the options database (under the
   matrix's prefix), else auto and on. */
static PetscErrorCode TuneSettings(Mat A, PetscBool *tune, PetscBool *cache, size_t *min_bytes)
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscBool       set, flg;
  PetscEnum       v = (PetscEnum)MAT_BINBCSR_TUNE_AUTO;

  PetscFunctionBegin;
  if (a->tune < 0) {
    PetscCall(PetscOptionsGetEnum(((PetscObject)A)->options, ((PetscObject)A)->prefix, "-mat_binbcsr_tune",
                                  MatBinBCSRTunes, &v, &set));
    a->tune = set ? (PetscInt)v : (PetscInt)MAT_BINBCSR_TUNE_AUTO;
  }
  if (a->tune_cache < 0) {
    flg = PETSC_TRUE;
    PetscCall(PetscOptionsGetBool(((PetscObject)A)->options, ((PetscObject)A)->prefix,
                                  "-mat_binbcsr_tune_cache", &flg, &set));
    a->tune_cache = flg ? 1 : 0;
  }
  {
    PetscInt kib = min_tune_kib; /* the size below which tuning is skipped (tests tune small matrices) */
    PetscCall(PetscOptionsGetInt(((PetscObject)A)->options, ((PetscObject)A)->prefix,
                                 "-mat_binbcsr_tune_min_kib", &kib, &set));
    PetscCheck(kib >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "-mat_binbcsr_tune_min_kib %" PetscInt_FMT " must be >= 0", kib);
    *min_bytes = (size_t)kib << 10;
  }
  *tune  = a->tune == (PetscInt)MAT_BINBCSR_TUNE_AUTO ? PETSC_TRUE : PETSC_FALSE;
  *cache = a->tune_cache ? PETSC_TRUE : PETSC_FALSE;
  PetscFunctionReturn(0);
}

static void SetInfo(Mat_SeqBinBCSR *a, const std::string &s)
{
  PetscStrncpy(a->tune_info, s.c_str(), sizeof(a->tune_info));
}

static std::string Fmt(const char *f, double x)
{
  char buf[64];
  snprintf(buf, sizeof(buf), f, x);
  return buf;
}

PetscErrorCode MatSeqBinBCSRTune(Mat A, const PetscInt bi[], const PetscInt bj[])
{
  Mat_SeqBinBCSR *a = (Mat_SeqBinBCSR *)A->data;
  PetscBool       tune, use_cache, found;
  const PetscInt  bs = a->bs, mbs = a->mbs, bw_default = BinBCSRDefaultBinWidth(bs);
  const size_t    vsize = a->precision == MAT_BINBCSR_PRECISION_SINGLE ? sizeof(float) : sizeof(MatScalar);
  PetscLogDouble  t_start, t_end;
  size_t          min_bytes;

  PetscFunctionBegin;
  a->tune_info[0] = 0;
  if (a->kernel_tuned) { /* the last build's choice, not the user's: free again */
    a->kernel       = MAT_BINBCSR_KERNEL_AUTO;
    a->kernel_tuned = PETSC_FALSE;
  }
  const PetscBool body_free = a->kernel == MAT_BINBCSR_KERNEL_AUTO ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(TuneSettings(A, &tune, &use_cache, &min_bytes));
  if (!tune) {
    SetInfo(a, "off (-mat_binbcsr_tune off)");
    PetscFunctionReturn(0);
  }
  if (a->bw_set && a->streams_set && !body_free) {
    SetInfo(a, "nothing to tune: bin width, streams and kernel set explicitly");
    PetscFunctionReturn(0);
  }
  if (bs != 1 && bs != 3) {
    SetInfo(a, "none: block size " + std::to_string(bs) + " has no vectorised sweep to tune");
    PetscFunctionReturn(0);
  }
  if (a->bw_set && a->bw != 4 && a->bw != 8 && a->bw != 16 && a->bw != 32) {
    SetInfo(a, "none: bin width " + std::to_string(a->bw) +
                 " (set) has no vectorised sweep, streams do not apply");
    PetscFunctionReturn(0);
  }
  PetscCall(PetscLogEventBegin(MAT_BinBCSR_Tune, A, 0, 0, 0));
  PetscCall(PetscTime(&t_start));
  /* the class of the pattern: stored blocks (upper ones for symmetric storage), their spread */
  double nz = 0, sq = 0;
  for (PetscInt r = 0; r < mbs; r++) {
    double n = (double)(bi[r + 1] - bi[r]);
    if (a->sym) {
      n = 0;
      for (PetscInt p = bi[r]; p < bi[r + 1]; p++) n += bj[p] >= r;
    }
    nz += n;
    sq += n * n;
  }
  const double mean   = mbs ? nz / mbs : 0,
               cv     = mean > 0 ? std::sqrt(std::max(0.0, sq / mbs - mean * mean)) / mean : 0;
  const size_t vbytes = (size_t)nz * a->bs2 * vsize;
  if (vbytes < min_bytes) {
    SetInfo(a, "none: " + std::to_string(vbytes >> 10) + " KiB of values (below " +
                 std::to_string(min_bytes >> 10) + " KiB any layout is as fast; -mat_binbcsr_tune_min_kib)");
    PetscCall(PetscLogEventEnd(MAT_BinBCSR_Tune, A, 0, 0, 0));
    PetscFunctionReturn(0);
  }
  const std::string key =
    BinBCSRTuneMachineKey() + "\t" +
    MatrixClass(a, vbytes, mean, cv, a->bw_set, a->streams_set, body_free ? PETSC_FALSE : PETSC_TRUE);
  if (use_cache) {
    BinBCSRTuneChoice c;
    PetscCall(BinBCSRTuneCacheLookup(key, &c, &found));
    if (found && (!a->bw_set || c.bw == a->bw) && (!a->streams_set || c.streams == a->streams) &&
        (body_free || c.kernel == (PetscInt)a->kernel) &&
        (c.bw == 4 || c.bw == 8 || c.bw == 16 || (c.bw == 32 && bs == 1))) {
      a->bw      = c.bw;
      a->streams = c.streams;
      if (body_free && c.kernel != (PetscInt)MAT_BINBCSR_KERNEL_AUTO) {
        a->kernel       = (MatBinBCSRKernel)c.kernel;
        a->kernel_tuned = PETSC_TRUE;
      }
      PetscCall(PetscTime(&t_end));
      SetInfo(a, "bin width " + std::to_string(c.bw) + ", streams " + std::to_string(c.streams) +
                   ", kernel " + MatBinBCSRKernels[c.kernel] + " from the cache " + BinBCSRTuneCachePath() +
                   " (" + Fmt("%.3f", 1e3 * (t_end - t_start)) + " ms)");
      PetscCall(PetscInfo(A, "Tuning: %s\n", a->tune_info));
      PetscCall(PetscLogEventEnd(MAT_BinBCSR_Tune, A, 0, 0, 0));
      PetscFunctionReturn(0);
    }
  }

  /* the sample: about twice the last-level cache (so it streams from memory as the matrix does), at
     most what 20 products read in the budget at ~20 GB/s */
  const long llc    = binbcsr::last_level_cache_bytes();
  size_t     target = std::min<size_t>(llc > 0 ? 2 * (size_t)llc : (size_t)64 << 20, (size_t)48 << 20);
  {
    PetscInt  mib = 0;
    PetscBool set;
    PetscCall(PetscOptionsGetInt(((PetscObject)A)->options, ((PetscObject)A)->prefix,
                                 "-mat_binbcsr_tune_sample_mib", &mib, &set));
    PetscCheck(!set || mib > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
               "-mat_binbcsr_tune_sample_mib %" PetscInt_FMT " must be > 0", mib);
    if (set) target = (size_t)mib << 20;
  }
  const double row_bytes = mbs ? (double)(vbytes + (size_t)nz * sizeof(PetscInt)) / mbs : 1;
  PetscInt nr = (PetscInt)std::min<double>((double)mbs, std::max(64.0, target / std::max(row_bytes, 1.0)));
  if (nr < mbs) nr = std::max<PetscInt>(32, nr / 32 * 32);
  const PetscInt r0 = nr < mbs ? (mbs - nr) / 2 / 32 * 32 : 0;
  const Sample   s  = Slab(a, bi, bj, r0, nr);

  std::vector<PetscInt> widths, counts;
  if (a->bw_set) widths = {a->bw};
  else { /* the default first: the stream counts are compared at it */ widths = {bw_default};
    for (PetscInt bw : {4, 8, 16, 32})
      if (bw != bw_default && (bw < 32 || bs == 1)) widths.push_back(bw);
  }
  if (a->streams_set) counts = {a->streams};
  else counts = {1, 2, 4, 8};

  Timer tm;
  tm.cold = vbytes > (llc > 0 ? (size_t)llc : (size_t)32 << 20);
  std::vector<Tried> tried;
  PetscInt           skipped = 0;
  Mat                best_T  = nullptr;
  Tried              best    = {widths[0], counts[0], 1e30, (PetscInt)a->kernel};
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, s.nc * bs, &tm.x));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, s.nr * bs, &tm.y));
  PetscCall(VecSet(tm.x, 1.0));
  PetscCall(VecSet(tm.y, 0.0));
  /* times bw with the stream counts ks (two rounds, the minimum of each); T kept when it holds the best */
  auto time_width = [&](PetscInt bw, const std::vector<PetscInt> &ks, Mat T) -> PetscErrorCode {
    std::vector<double> sec(ks.size(), 1e30);
    double              warm;
    PetscFunctionBegin;
    if (!T) {
      PetscCall(SampleMatrix(a, s, bw, &T));
      PetscCall(tm.Time(T, ks[0], &warm)); /* caches, TLB */
    }
    for (int round = 0; round < 2; round++)
      for (size_t i = 0; i < ks.size(); i++) {
        double t;
        PetscCall(tm.Time(T, ks[i], &t));
        sec[i] = std::min(sec[i], t);
      }
    bool kept = false;
    for (size_t i = 0; i < ks.size(); i++) {
      tried.push_back({bw, ks[i], sec[i], (PetscInt)((Mat_SeqBinBCSR *)T->data)->kernel});
      if (sec[i] < best.sec) {
        best = tried.back();
        if (best_T != T) {
          PetscCall(MatDestroy(&best_T));
          best_T = T;
        }
        kept = true;
      }
    }
    if (!kept && T != best_T) PetscCall(MatDestroy(&T));
    PetscFunctionReturn(0);
  };
  /* the other body sets at the best width and streams, where their body differs from the default's */
  auto time_bodies = [&]() -> PetscErrorCode {
    Mat_SeqBinBCSR                *t    = (Mat_SeqBinBCSR *)best_T->data;
    const binbcsr::Shape           sh   = {(int)bs, (int)best.bw, (int)best.K,
                                           a->precision == MAT_BINBCSR_PRECISION_SINGLE, a->sym ? true : false};
    std::vector<binbcsr::MultBody> seen = {binbcsr::select_body(sh, binbcsr::BodySet::Auto).mult};
    PetscFunctionBegin;
    for (int k = (int)MAT_BINBCSR_KERNEL_PORTABLE; k <= (int)MAT_BINBCSR_KERNEL_AVX512; k++) {
      if (!binbcsr::body_set_available((binbcsr::BodySet)k)) continue;
      const binbcsr::Body b = binbcsr::select_body(sh, (binbcsr::BodySet)k);
      if (std::find(seen.begin(), seen.end(), b.mult) != seen.end() || b.set != (binbcsr::BodySet)k)
        continue; /* the same body, or a fallback */
      seen.push_back(b.mult);
      if (!tm.Admits(2, best.sec)) {
        skipped++;
        continue;
      }
      double sec = 1e30, s1;
      t->kernel  = (MatBinBCSRKernel)k;
      for (int round = 0; round < 2; round++) {
        PetscCall(tm.Time(best_T, best.K, &s1));
        sec = std::min(sec, s1);
      }
      tried.push_back({best.bw, best.K, sec, (PetscInt)k});
      if (sec < best.sec) best = tried.back();
    }
    t->kernel = (MatBinBCSRKernel)best.kernel;
    PetscFunctionReturn(0);
  };
  PetscCall(time_width(widths[0], counts, nullptr));
  const PetscInt k_first = best.K;
  for (size_t i = 1; i < widths.size(); i++) {
    if (!tm.Admits(3, best.sec)) {
      skipped++;
      continue;
    }
    PetscCall(time_width(widths[i], {k_first}, nullptr));
  }
  if (best.bw != widths[0] && counts.size() > 1) {
    std::vector<PetscInt> rest;
    for (PetscInt K : counts)
      if (K != k_first) rest.push_back(K);
    if (tm.Admits(2 * (PetscInt)rest.size(), best.sec)) PetscCall(time_width(best.bw, rest, best_T));
    else skipped += (PetscInt)rest.size();
  }
  if (body_free) PetscCall(time_bodies());
  PetscCall(MatDestroy(&best_T));
  PetscCall(VecDestroy(&tm.x));
  PetscCall(VecDestroy(&tm.y));
  a->bw      = best.bw;
  a->streams = best.K;
  if (body_free && best.kernel != (PetscInt)MAT_BINBCSR_KERNEL_AUTO) {
    a->kernel       = (MatBinBCSRKernel)best.kernel;
    a->kernel_tuned = PETSC_TRUE;
  }
  if (use_cache) PetscCall(BinBCSRTuneCacheStore(key, BinBCSRTuneChoice{best.bw, best.K, best.kernel}));
  PetscCall(PetscTime(&t_end));

  /* the report: what was tried, the choice against the untuned default, what it cost */
  double      t_default = -1;
  std::string list;
  for (const Tried &t : tried) {
    list += (list.empty() ? "" : ", ") + std::to_string(t.bw) + "/" + std::to_string(t.K) +
            (t.kernel != (body_free ? (PetscInt)MAT_BINBCSR_KERNEL_AUTO : (PetscInt)a->kernel)
               ? std::string("/") + MatBinBCSRKernels[t.kernel]
               : std::string("")) +
            " " + Fmt("%.3g", 1e3 * t.sec);
    if (t.bw == (a->bw_set ? a->bw : bw_default) &&
        t.K == (a->streams_set ? a->streams : BINBCSR_DEFAULT_STREAMS) &&
        (!body_free || t.kernel == (PetscInt)MAT_BINBCSR_KERNEL_AUTO))
      t_default = t.sec;
  }
  std::string info = "bin width " + std::to_string(best.bw) + ", streams " + std::to_string(best.K) +
                     ", kernel " + MatBinBCSRKernels[best.kernel] + " measured on block rows " +
                     std::to_string(r0) + ".." + std::to_string(r0 + nr - 1) + " of " + std::to_string(mbs) +
                     (tm.cold ? ", read from memory" : ", in cache") +
                     " (ms per sample product, width/streams[/kernel]: " + list +
                     (skipped ? "; " + std::to_string(skipped) + " left out by the budget" : "") + ")";
  const double cost = t_end - t_start;
  info += "; cost " + Fmt("%.1f", 1e3 * cost) + " ms (" + Fmt("%.1f", 1e3 * tm.seconds) + " ms CPU in " +
          std::to_string(tm.products) + " sample products)";
  if (t_default > 0) {
    const double gain =
      (t_default - best.sec) * (double)mbs / (double)nr; /* per product of the whole matrix */
    info += "; " + Fmt("%.2f", t_default / best.sec) + "x the default";
    if (gain > 0) info += ", pays back after " + std::to_string((long)std::ceil(cost / gain)) + " products";
  }
  SetInfo(a, info);
  PetscCall(PetscInfo(A, "Tuning: %s\n", a->tune_info));
  PetscCall(PetscLogEventEnd(MAT_BinBCSR_Tune, A, 0, 0, 0));
  PetscFunctionReturn(0);
}

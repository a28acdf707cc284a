/* MATSEQBINBCSR: the per-machine tuning of the bin width, the stream count, the body set, the
   software prefetch distance and the x load (-mat_binbcsr_tune).

   It runs where a layout is built from a final pattern (MatSeqBinBCSRBuildLayout: first final
   assembly, COO preallocation, conversion, load), before the layout exists, so the matrix is built
   once, with the chosen width: no second copy of the values, and the COO maps, the colouring of
   symmetric storage and the parts of an MPI matrix only ever see the final layout. The timing needs
   only the pattern: products of a sample (a slab of consecutive block rows, about twice the
   last-level cache, or the whole matrix when smaller) with the candidate layouts, values set to a
   constant (the time of a product does not depend on them). A matrix larger than the last-level cache
   is read from memory by every product, so the sample is too: its arrays are dropped from the caches
   before each timed product.

   Candidates, in races (rounds of the candidates in turn, as many as the budget of about 40 products
   or 50 ms of product time admits): the widths (4, 8, 16, and 32 for bs 1) at one stream, with the
   untuned default beside them; the stream counts 1, 2, 4, 8 at the best width; the other kernel body
   sets the CPU has (kernels/binbcsr_dispatch.h) at the best width and streams; the prefetch distances
   0, 1024 and 4096 bytes at the best of those; x by loads or by gathers where the best is the AVX-512
   whole product of 3x3 blocks at width 8 (MatBinBCSRSetXLoad); last the configurations within 10% of
   the best, again. A width, stream count, body set, prefetch distance or x load given explicitly
   (option or MatBinBCSRSet*) is kept and only the others are tuned. Products are timed in this
   thread's CPU time (the budget too); the cost reported is wall time. */
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
constexpr PetscInt budget_products = 40; /* 30 before the prefetch distances were timed too */
constexpr PetscInt min_tune_kib =
  512; /* smaller matrices live in L2: any layout does (-mat_binbcsr_tune_min_kib) */

/* The matrix class of a cache key: block size, precision, storage, size bucket (log2 of the value
   bytes), mean row length bucket (log2) and row-length spread (coefficient of variation in quarters),
   plus the parameters set explicitly (their values are part of the question). */
std::string MatrixClass(const Mat_SeqBinBCSR *a, size_t vbytes, double mean, double cv, PetscBool bw_fixed,
                        PetscBool k_fixed, PetscBool body_fixed, PetscBool pf_fixed, PetscBool x_fixed)
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
  if (pf_fixed) c += " prefetch=" + std::to_string(a->prefetch);
  if (x_fixed) c += std::string(" xload=") + MatBinBCSRXLoads[a->xload];
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
  PetscInt products     = 0;
  double   seconds      = 0; /* time in timed products */
  double   budget       = 0; /* seconds of product time */
  PetscInt max_products = 0;
  bool     cold         = false; /* the sample's arrays dropped from the caches before each product */

  /* Seconds of one product of T with K streams (the product op itself: no log events, no checks).
     No product runs untimed to warm up: the sample's pages are written when it is filled, and its
     arrays are read from memory at every product anyway (cold). */
  PetscErrorCode Time(Mat T, PetscInt K, PetscInt pf, PetscInt xg, double *sec)
  {
    Mat_SeqBinBCSR *t = (Mat_SeqBinBCSR *)T->data;

    PetscFunctionBegin;
    t->streams  = K;
    t->prefetch = pf;
    t->xload    = (MatBinBCSRXLoad)xg;
    PetscCall(MatSeqBinBCSRXLoadHint(T)); /* outside the timed product */
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
    const double t0 = binbcsr::thread_cpu_seconds();
    PetscCall(MatMult_SeqBinBCSR(T, x, y));
    *sec = binbcsr::thread_cpu_seconds() - t0;
    products++;
    seconds += *sec;
    PetscFunctionReturn(0);
  }
  bool Admits(PetscInt n, double per) const
  {
    return products + n <= max_products && seconds + n * per <= budget;
  }
};

/* Whether the x load is the tuner's to choose: not set, and a whole product of 3x3 blocks that may run
   at width 8 with the AVX-512 body (the only one that reads it). */
bool XLoadFree(const Mat_SeqBinBCSR *a)
{
  return !a->xload_set && a->bs == 3 && !a->sym && (!a->bw_set || a->bw == 8) &&
         (a->kernel == MAT_BINBCSR_KERNEL_AUTO || a->kernel == MAT_BINBCSR_KERNEL_AVX512) &&
         binbcsr::body_set_available(binbcsr::BodySet::AVX512);
}

/* After the choice: where the x load was the tuner's and the chosen shape reads it, the matrix's first
   products decide it again (binbcsr_mult.cpp). */
void StartXLoadTrial(Mat_SeqBinBCSR *a)
{
  if (!XLoadFree(a) || !MatSeqBinBCSRReadsXLoad(a)) return;
  a->xload_chosen = (PetscInt)a->xload;
  a->xload_sec[0] = a->xload_sec[1] = 1e30;
  a->xload_trial                    = BINBCSR_XLOAD_TRIAL;
}

struct Tried {
  PetscInt bw, K;
  double   sec;
  PetscInt kernel;       /* MatBinBCSRKernel; AUTO: the dispatch's default body */
  PetscInt pf;           /* prefetch distance, bytes */
  PetscInt xg       = 0; /* MatBinBCSRXLoad */
  PetscInt products = 0; /* timed so far */
};

} // namespace

/* Resolves the tune settings: the values set, else the options database (under the matrix's
   prefix), else auto, cache on, and the defaults of the benchmark knobs. */
PetscErrorCode BinBCSRTuneSettingsGet(Mat A, BinBCSRTuneSettings *st)
{
  Mat_SeqBinBCSR *a   = (Mat_SeqBinBCSR *)A->data;
  PetscOptions    db  = ((PetscObject)A)->options;
  const char     *pre = ((PetscObject)A)->prefix;
  PetscBool       set, flg;
  PetscEnum       v   = (PetscEnum)MAT_BINBCSR_TUNE_AUTO;
  PetscInt        kib = min_tune_kib, mib = 0, ms = -1;

  PetscFunctionBegin;
  if (a->tune < 0) {
    PetscCall(PetscOptionsGetEnum(db, pre, "-mat_binbcsr_tune", MatBinBCSRTunes, &v, &set));
    a->tune = set ? (PetscInt)v : (PetscInt)MAT_BINBCSR_TUNE_AUTO;
  }
  if (a->tune_cache < 0) {
    flg = PETSC_TRUE;
    PetscCall(PetscOptionsGetBool(db, pre, "-mat_binbcsr_tune_cache", &flg, &set));
    a->tune_cache = flg ? 1 : 0;
  }
  /* the size below which tuning is skipped (tests tune small matrices) */
  PetscCall(PetscOptionsGetInt(db, pre, "-mat_binbcsr_tune_min_kib", &kib, &set));
  PetscCheck(kib >= 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "-mat_binbcsr_tune_min_kib %" PetscInt_FMT " must be >= 0", kib);
  PetscCall(PetscOptionsGetInt(db, pre, "-mat_binbcsr_tune_sample_mib", &mib, &set));
  PetscCheck(!set || mib > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "-mat_binbcsr_tune_sample_mib %" PetscInt_FMT " must be > 0", mib);
  PetscCall(PetscOptionsGetInt(db, pre, "-mat_binbcsr_tune_budget_ms", &ms, &set));
  PetscCheck(!set || ms > 0, PETSC_COMM_SELF, PETSC_ERR_ARG_OUTOFRANGE,
             "-mat_binbcsr_tune_budget_ms %" PetscInt_FMT " must be > 0", ms);
  st->tune         = a->tune == (PetscInt)MAT_BINBCSR_TUNE_AUTO ? PETSC_TRUE : PETSC_FALSE;
  st->cache        = a->tune_cache ? PETSC_TRUE : PETSC_FALSE;
  st->min_bytes    = (size_t)kib << 10;
  st->sample_bytes = (size_t)mib << 20;
  st->budget       = set ? 1e-3 * (double)ms : budget_seconds;
  st->products     = set ? PETSC_MAX_INT : budget_products;
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
  Mat_SeqBinBCSR     *a = (Mat_SeqBinBCSR *)A->data;
  BinBCSRTuneSettings set;
  PetscBool           found;
  const PetscInt      bs = a->bs, mbs = a->mbs, bw_default = BinBCSRDefaultBinWidth(bs);
  const size_t   vsize = a->precision == MAT_BINBCSR_PRECISION_SINGLE ? sizeof(float) : sizeof(MatScalar);
  PetscLogDouble t_start, t_end;

  PetscFunctionBegin;
  a->tune_info[0] = 0;
  if (a->kernel_tuned) { /* the last build's choice, not the user's: free again */
    a->kernel       = MAT_BINBCSR_KERNEL_AUTO;
    a->kernel_tuned = PETSC_FALSE;
  }
  if (!a->xload_set) a->xload = MAT_BINBCSR_XLOAD_LOADS; /* likewise */
  a->xload_trial            = 0;
  const PetscBool body_free = a->kernel == MAT_BINBCSR_KERNEL_AUTO ? PETSC_TRUE : PETSC_FALSE;
  PetscCall(BinBCSRTuneSettingsGet(A, &set));
  const PetscBool use_cache = set.cache;
  if (!set.tune) {
    SetInfo(a, "off (-mat_binbcsr_tune off)");
    PetscFunctionReturn(0);
  }
  if (a->bw_set && a->streams_set && !body_free && a->prefetch_set && !XLoadFree(a)) {
    SetInfo(a, "nothing to tune: bin width, streams, kernel, prefetch and x load set explicitly");
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
  if (vbytes < set.min_bytes) {
    SetInfo(a, "none: " + std::to_string(vbytes >> 10) + " KiB of values (below " +
                 std::to_string(set.min_bytes >> 10) +
                 " KiB any layout is as fast; -mat_binbcsr_tune_min_kib)");
    PetscCall(PetscLogEventEnd(MAT_BinBCSR_Tune, A, 0, 0, 0));
    PetscFunctionReturn(0);
  }
  const std::string key = BinBCSRTuneMachineKey() + "\t" +
                          MatrixClass(a, vbytes, mean, cv, a->bw_set, a->streams_set,
                                      body_free ? PETSC_FALSE : PETSC_TRUE, a->prefetch_set, a->xload_set);
  if (use_cache) {
    BinBCSRTuneChoice c;
    PetscCall(BinBCSRTuneCacheLookup(key, &c, &found));
    if (found && (!a->bw_set || c.bw == a->bw) && (!a->streams_set || c.streams == a->streams) &&
        (body_free || c.kernel == (PetscInt)a->kernel) && (!a->prefetch_set || c.prefetch == a->prefetch) &&
        (!a->xload_set || c.xload == (PetscInt)a->xload) &&
        (c.bw == 4 || c.bw == 8 || c.bw == 16 || (c.bw == 32 && bs == 1))) {
      a->bw       = c.bw;
      a->streams  = c.streams;
      a->prefetch = c.prefetch;
      a->xload    = (MatBinBCSRXLoad)c.xload;
      if (body_free && c.kernel != (PetscInt)MAT_BINBCSR_KERNEL_AUTO) {
        a->kernel       = (MatBinBCSRKernel)c.kernel;
        a->kernel_tuned = PETSC_TRUE;
      }
      StartXLoadTrial(a);
      PetscCall(PetscTime(&t_end));
      SetInfo(a, "bin width " + std::to_string(c.bw) + ", streams " + std::to_string(c.streams) +
                   ", kernel " + MatBinBCSRKernels[c.kernel] + ", prefetch " + std::to_string(c.prefetch) +
                   ", x load " + MatBinBCSRXLoads[c.xload] + " from the cache " + BinBCSRTuneCachePath() +
                   " (" + Fmt("%.3f", 1e3 * (t_end - t_start)) + " ms)");
      PetscCall(PetscInfo(A, "Tuning: %s\n", a->tune_info));
      PetscCall(PetscLogEventEnd(MAT_BinBCSR_Tune, A, 0, 0, 0));
      PetscFunctionReturn(0);
    }
  }

  /* The sample: at most 24 MB, and about twice the last-level cache when that is smaller. It is read
     from memory at every product (cold) when the matrix is, so it need not exceed the cache; it has to
     be small enough that the budget admits every race below with time to spare: a 48 MB sample of the
     48^3 stencil took 4-8 ms per product on a Zen 4 core, the budget ran out after the stream counts
     at the default width, and width 4 (1.2-1.3x faster on the whole matrix there) was never timed. */
  const long llc    = binbcsr::last_level_cache_bytes();
  size_t     target = std::min<size_t>(llc > 0 ? 2 * (size_t)llc : (size_t)64 << 20, (size_t)24 << 20);
  if (set.sample_bytes) target = set.sample_bytes;
  const double row_bytes = mbs ? (double)(vbytes + (size_t)nz * sizeof(PetscInt)) / mbs : 1;
  PetscInt nr = (PetscInt)std::min<double>((double)mbs, std::max(64.0, target / std::max(row_bytes, 1.0)));
  if (nr < mbs) nr = std::max<PetscInt>(32, nr / 32 * 32);
  const PetscInt r0 = nr < mbs ? (mbs - nr) / 2 / 32 * 32 : 0;
  const Sample   s  = Slab(a, bi, bj, r0, nr);

  std::vector<PetscInt> widths, counts;
  if (a->bw_set) widths = {a->bw};
  else {
    widths = {bw_default};
    for (PetscInt bw : {4, 8, 16, 32})
      if (bw != bw_default && (bw < 32 || bs == 1)) widths.push_back(bw);
  }
  if (a->streams_set) counts = {a->streams};
  else counts = {1, 2, 4, 8};

  Timer tm;
  /* read from memory when the matrix's arrays exceed half the last-level cache: a solver's vectors
     share that cache, and a 35 MB matrix (the 32^3 stencil in single, values and columns) streams from
     memory through a 32 MiB one, while its 24 MB sample stayed in it and ranked the bodies by how fast
     they compute (the tuned choice was 1.2-1.4x slower than the best on the whole matrix). The half is
     of what stays in the caches as measured, not of what the system claims: a Xeon VM claims its
     host's 480 MiB, and there the 32^3 and 48^3 stencils (67 and 226 MB in double) were read from
     memory at every product; timed in cache, their tuned layouts ran 1.24-1.30x slower than the best. */
  const size_t matrix_bytes = vbytes + (size_t)nz * sizeof(PetscInt),
               claimed      = llc > 0 ? (size_t)llc : (size_t)32 << 20;
  tm.cold         = matrix_bytes > claimed / 2 || !binbcsr::stays_in_cache(2 * matrix_bytes, claimed);
  tm.budget       = set.budget;
  tm.max_products = set.products;
  std::vector<Tried> tried; /* every configuration timed, in the order first timed */
  std::vector<Mat>   layouts(widths.size(), nullptr);
  PetscInt           skipped = 0;
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, s.nc * bs, &tm.x));
  PetscCall(VecCreateSeq(PETSC_COMM_SELF, s.nr * bs, &tm.y));
  PetscCall(VecSet(tm.x, 1.0));
  PetscCall(VecSet(tm.y, 0.0));
  auto layout = [&](PetscInt bw, Mat *T) -> PetscErrorCode {
    PetscFunctionBegin;
    const size_t i = (size_t)(std::find(widths.begin(), widths.end(), bw) - widths.begin());
    if (!layouts[i]) PetscCall(SampleMatrix(a, s, bw, &layouts[i]));
    *T = layouts[i];
    PetscFunctionReturn(0);
  };
  auto entry = [&](const Tried &c) -> Tried & {
    for (Tried &t : tried)
      if (t.bw == c.bw && t.K == c.K && t.kernel == c.kernel && t.pf == c.pf && t.xg == c.xg) return t;
    tried.push_back(c);
    return tried.back();
  };
  /* Rounds of the candidates in turn (A B C, A B C, ...), as many as asked and the budget admits
     (the first round of the first race always runs): a drift of the memory bandwidth, which on a
     shared machine moves by 30% from one second to the next, then hits every candidate alike instead
     of deciding between them. Each configuration's minimum over all its products counts. */
  auto race = [&](std::vector<Tried> cs, int rounds) -> PetscErrorCode {
    PetscFunctionBegin;
    for (int round = 0; round < rounds; round++) {
      double per = 0; /* the slowest known product of the round */
      for (const Tried &c : cs) per = std::max(per, entry(c).sec);
      if ((tm.products || round) &&
          !tm.Admits((PetscInt)cs.size(), per < 1e29 ? per : tm.seconds / tm.products)) {
        if (round == 0) /* the configurations never timed are left out */
          skipped += (PetscInt)std::count_if(cs.begin(), cs.end(),
                                             [&](const Tried &c) { return entry(c).sec >= 1e29; });
        break;
      }
      for (const Tried &c : cs) {
        Mat    T;
        double t;
        PetscCall(layout(c.bw, &T));
        ((Mat_SeqBinBCSR *)T->data)->kernel = (MatBinBCSRKernel)c.kernel;
        PetscCall(tm.Time(T, c.K, c.pf, c.xg, &t));
        Tried &e = entry(c);
        e.sec    = std::min(e.sec, t);
        e.products++;
      }
      /* a candidate 30% behind the best after two rounds is out; after one round a product slowed by
         another process's memory traffic (1.8x here) would decide alone */
      double lead = 1e30;
      for (const Tried &c : cs) lead = std::min(lead, entry(c).sec);
      cs.erase(
        std::remove_if(cs.begin(), cs.end(),
                       [&](const Tried &c) { return entry(c).products >= 2 && entry(c).sec > 1.3 * lead; }),
        cs.end());
      if (cs.size() < 2) break;
    }
    PetscFunctionReturn(0);
  };
  auto best_of = [&](const std::vector<Tried> &cs) {
    Tried b = entry(cs[0]);
    for (const Tried &c : cs) /* the minimum over every product of the configuration */
      if (entry(c).sec < b.sec) b = entry(c);
    return b;
  };
  const PetscInt kernel0 = (PetscInt)a->kernel, K0 = a->streams_set ? a->streams : 1,
                 pf0 = a->prefetch_set ? a->prefetch : BINBCSR_DEFAULT_PREFETCH,
                 xg0 = a->xload_set ? (PetscInt)a->xload : (PetscInt)MAT_BINBCSR_XLOAD_LOADS;
  /* 1. the widths at one stream (the fastest count on most machines, and the cheapest product), with
        the untuned default beside them: what the choice gains is measured against it */
  std::vector<Tried> cs;
  for (PetscInt bw : widths) cs.push_back({bw, K0, 1e30, kernel0, pf0, xg0});
  const Tried dflt = {a->bw_set ? a->bw : bw_default,
                      a->streams_set ? a->streams : BINBCSR_DEFAULT_STREAMS,
                      1e30,
                      kernel0,
                      pf0,
                      xg0};
  if (dflt.K != K0) cs.push_back(dflt);
  PetscCall(race(cs, 3));
  Tried best = best_of(cs);
  /* 2. the stream counts at the best width */
  if (counts.size() > 1) {
    cs.clear();
    for (PetscInt K : counts) cs.push_back({best.bw, K, 1e30, kernel0, pf0, xg0});
    PetscCall(race(cs, 2));
    best = best_of(cs);
  }
  /* 3. the other body sets the CPU has, where their body for the shape differs from the default's */
  if (body_free) {
    const binbcsr::Shape           sh   = {(int)bs, (int)best.bw, (int)best.K,
                                           a->precision == MAT_BINBCSR_PRECISION_SINGLE, a->sym ? true : false};
    std::vector<binbcsr::MultBody> seen = {binbcsr::select_body(sh, binbcsr::BodySet::Auto).mult};
    cs                                  = {best};
    for (int k = (int)MAT_BINBCSR_KERNEL_PORTABLE; k <= (int)MAT_BINBCSR_KERNEL_AVX512; k++) {
      if (!binbcsr::body_set_available((binbcsr::BodySet)k)) continue;
      const binbcsr::Body b = binbcsr::select_body(sh, (binbcsr::BodySet)k);
      if (std::find(seen.begin(), seen.end(), b.mult) != seen.end() || b.set != (binbcsr::BodySet)k)
        continue; /* the same body, or a fallback */
      seen.push_back(b.mult);
      cs.push_back({best.bw, best.K, 1e30, (PetscInt)k, pf0, xg0});
    }
    if (cs.size() > 1) {
      PetscCall(race(cs, 2));
      best = best_of(cs);
    }
  }
  /* 4. the software prefetch distances at the best so far: on a Zen 5 VM 4 KiB ahead (the Xeon's
        choice) made the 48^3 stencil's product 1.7x slower than none in some minutes and none of the
        distances was ahead in others, so it is measured with the rest (docs/tuning.md) */
  if (!a->prefetch_set) {
    cs = {best};
    for (PetscInt pf : {(PetscInt)0, (PetscInt)1024, (PetscInt)4096})
      if (pf != best.pf) cs.push_back({best.bw, best.K, 1e30, best.kernel, pf, xg0});
    PetscCall(race(cs, 2));
    best = best_of(cs);
  }
  /* 4b. x by gathers in every slot group against loads where the bins allow, where the best runs the
        AVX-512 whole product of 3x3 blocks at width 8: on a Zen 5 VM gathers ran the 48^3 stencil in
        double about 10% faster and in single 1.4x slower (MatBinBCSRSetXLoad) */
  if (!a->xload_set) {
    const binbcsr::Shape sh = {(int)bs, (int)best.bw, (int)best.K,
                               a->precision == MAT_BINBCSR_PRECISION_SINGLE, a->sym ? true : false};
    if (BinBCSRShapeReadsXLoad(a->sym, bs, best.bw,
                               binbcsr::select_body(sh, (binbcsr::BodySet)best.kernel).set)) {
      Tried g = best;
      g.xg    = 1 - best.xg;
      g.sec   = 1e30;
      cs      = {best, g};
      PetscCall(race(cs, 2));
      best = best_of(cs);
    }
  }
  /* 5. the configurations within 10% of the best, again in turn: coordinate steps compared each
        parameter at the others' provisional values, and a near tie is where a drift decides */
  cs.clear();
  for (const Tried &t : tried)
    if (t.sec < 1.1 * best.sec) cs.push_back(t);
  if (cs.size() > 1) {
    PetscCall(race(cs, 2));
    best = best_of(cs);
  }
  for (Mat &T : layouts) PetscCall(MatDestroy(&T));
  PetscCall(VecDestroy(&tm.x));
  PetscCall(VecDestroy(&tm.y));
  a->bw       = best.bw;
  a->streams  = best.K;
  a->prefetch = best.pf;
  if (!a->xload_set) a->xload = (MatBinBCSRXLoad)best.xg;
  if (body_free && best.kernel != (PetscInt)MAT_BINBCSR_KERNEL_AUTO) {
    a->kernel       = (MatBinBCSRKernel)best.kernel;
    a->kernel_tuned = PETSC_TRUE;
  }
  StartXLoadTrial(a);
  if (use_cache)
    PetscCall(BinBCSRTuneCacheStore(key, BinBCSRTuneChoice{best.bw, best.K, best.kernel, best.pf, best.xg}));
  PetscCall(PetscTime(&t_end));

  /* the report: what was tried, the choice against the untuned default, what it cost */
  double      t_default = -1;
  std::string list;
  for (const Tried &t : tried) {
    if (t.sec >= 1e29) continue; /* left out by the budget */
    list += (list.empty() ? "" : ", ") + std::to_string(t.bw) + "/" + std::to_string(t.K) +
            (t.kernel != (body_free ? (PetscInt)MAT_BINBCSR_KERNEL_AUTO : (PetscInt)a->kernel)
               ? std::string("/") + MatBinBCSRKernels[t.kernel]
               : std::string("")) +
            (t.pf != pf0 ? "/pf" + std::to_string(t.pf) : std::string("")) +
            (t.xg != dflt.xg ? std::string("/") + MatBinBCSRXLoads[t.xg] : std::string("")) + " " +
            Fmt("%.3g", 1e3 * t.sec);
    if (t.bw == dflt.bw && t.K == dflt.K && t.kernel == dflt.kernel && t.pf == dflt.pf && t.xg == dflt.xg &&
        t.sec < 1e29)
      t_default = t.sec;
  }
  std::string info = "bin width " + std::to_string(best.bw) + ", streams " + std::to_string(best.K) +
                     ", kernel " + MatBinBCSRKernels[best.kernel] + ", prefetch " + std::to_string(best.pf) +
                     ", x load " + MatBinBCSRXLoads[best.xg] + " measured on block rows " +
                     std::to_string(r0) + ".." + std::to_string(r0 + nr - 1) + " of " + std::to_string(mbs) +
                     (tm.cold ? ", read from memory" : ", in cache") +
                     " (ms per sample product, width/streams[/kernel][/pf bytes][/x load]: " + list +
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

/* After MatBinBCSRSetPrecision changed the precision of a built matrix: the choice was timed in the
   old precision, and on a Zen 4 core the 48^3 stencil's best width is 4 in double and 8 in single
   (1.3x apart each way). The width is the layout's and stays (a new layout would drop the COO maps and
   the colouring); the stream count, the body set, the prefetch distance and the x load, where the
   tuner chose them, are timed again in the new precision, on the pattern read back from the layout. */
PetscErrorCode MatSeqBinBCSRRetune(Mat A)
{
  Mat_SeqBinBCSR       *a = (Mat_SeqBinBCSR *)A->data;
  std::vector<PetscInt> bi(1, 0), bj;
  const PetscBool       bw_set = a->bw_set;

  PetscFunctionBegin;
  if (!a->built || a->tune != (PetscInt)MAT_BINBCSR_TUNE_AUTO) PetscFunctionReturn(0);
  if (a->streams_set && a->prefetch_set && !a->kernel_tuned && a->kernel != MAT_BINBCSR_KERNEL_AUTO &&
      !XLoadFree(a))
    PetscFunctionReturn(0);
  bj.reserve((size_t)a->nz);
  for (PetscInt r = 0; r < a->mbs; r++) { /* whole storage: every block; symmetric: the upper ones */
    if (a->sym)
      for (PetscInt p = a->row_off[r]; p < a->row_off[r + 1]; p++) bj.push_back(a->col[a->real_slot[p]]);
    else
      for (PetscInt k = 0; k < a->row_nz[r]; k++)
        bj.push_back(a->col[binbcsr::row_slot(a->bin_start, a->bw, r, k)]);
    bi.push_back((PetscInt)bj.size());
  }
  a->bw_set           = PETSC_TRUE;
  PetscErrorCode ierr = MatSeqBinBCSRTune(A, bi.data(), bj.data());
  a->bw_set           = bw_set;
  PetscCall(ierr);
  std::string info = std::string("after the precision change, at the layout's bin width: ") + a->tune_info;
  SetInfo(a, info);
  PetscFunctionReturn(0);
}

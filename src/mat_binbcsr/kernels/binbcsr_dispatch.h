/*
   The one place that picks the body of a product. A body is a CPU function that runs one product of a
   whole matrix for one shape: block size, bin width, value precision, storage (whole or symmetric) and
   the number of runs of bins swept side by side (streams). The body sets are
     portable  kernels/portable/  the per-lane definition (binbcsr_kernels.h) driven bin by bin: every
                                  shape, the reference the others are tested against;
     avx2      kernels/avx2/      the same drivers compiled for AVX2 + FMA;
     avx512    kernels/avx512/    the drivers compiled for AVX-512 with the hand-written 3x3, width 8
                                  bodies (avx512/binbcsr_avx512.h).
   Each set is compiled in its own translation unit with its own target flags, so the library runs on
   any x86-64 and select_body() takes the best set this CPU has at run time (or the one asked for).

   Plain C++: no PETSc here (the PETSc glue is seq/binbcsr_mult.cpp and binbcsr_kernel_api.cpp).
*/
#ifndef BINBCSR_DISPATCH_H
#define BINBCSR_DISPATCH_H

#include "../../binbcsr_cpu.h" /* BodySet, body_set_name and the CPU query */

namespace binbcsr {

/* Everything a product reads, as plain pointers (32-bit indices, as the layout). */
struct BinMatrix {
  const int    *bin_start;                        /* [nbins + 1] */
  const int    *col;                              /* [nslots] */
  const int    *row_nz;                           /* [mbs] real blocks of each row */
  const int    *diag_slot;                        /* [mbs] */
  const double *val;                              /* double values, or NULL */
  const float  *valf;                             /* single values, or NULL */
  int           nbins, mbs, nbs, bs, bw, streams; /* nbs: block columns (x has nbs * bs entries) */
  int           prefetch; /* bytes the products prefetch the values ahead (0: none; prefetch_values) */
  bool          sym;
  /* [nbins] or NULL, whole storage, 3x3 blocks, width 8 (the AVX-512 body): each bin's XC_*
     (binbcsr_layout.h), XC_LANES where its slot groups mostly cannot load x_c as consecutive columns
     (near_unit_group), so that the body reads it lane by lane there without testing each group; NULL:
     test every group. A hint: every way reads the same x_c. */
  const unsigned char *bin_xload;
};

/* The shape a body is chosen for. */
struct Shape {
  int  bs, bw, streams;
  bool single, sym;
};

/* Whole storage: y = z + A x (z may be NULL or alias y). Symmetric storage: y += A x (the caller puts
   z or zero in y first). dot (may be NULL): *dot = x.y. acc: scratch of bs doubles. */
using MultBody = void (*)(const BinMatrix &, const double *x, const double *z, double *y, double *dot,
                          double *acc);
/* y += A^T x (whole storage). */
using MultTransposeBody = void (*)(const BinMatrix &, const double *x, double *y);

struct Body {
  MultBody          mult;
  MultTransposeBody mult_transpose;
  BodySet           set; /* the set the product body came from */
};

/* THE dispatch: the body for shape s from the set `want` (Auto: the best this CPU has). A set that
   has no specialised body for the shape falls back to the portable one (Body::set says which). */
Body select_body(const Shape &s, BodySet want);

/* Whether this build has the set and this CPU can run it (Auto and Portable: always). */
bool body_set_available(BodySet);
/* The best available set. */
BodySet best_body_set();

/* Each body set's table (its translation unit): fills b for shape s and returns true when the set has
   a body for it. Only select_body calls them. */
bool bodies_portable(const Shape &s, Body &b);
bool bodies_avx2(const Shape &s, Body &b);
bool bodies_avx512(const Shape &s, Body &b);

} // namespace binbcsr

#endif

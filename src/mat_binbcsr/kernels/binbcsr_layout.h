/*
   The whole-storage BIN-(B)CSR layout rule (src/mat_binbcsr/seq/binbcsr.h has the picture) as plain
   functions over a block CSR pattern: no PETSc, no STL, no allocation. MATSEQBINBCSR builds its bins
   with them after checking the pattern, and the CUDA benchmark (examples/gpu/) builds the same bins on a
   machine without PETSc, so both run the one layout the kernels are written for.

   Input: mbs block rows, row_ptr[mbs + 1], cols[row_ptr[mbs]] sorted and unique in each row (the caller
   checks). I is the index type (32-bit in this build).
*/
#ifndef BINBCSR_LAYOUT_H
#define BINBCSR_LAYOUT_H

namespace binbcsr {

/* bin_start[0 .. nbins] for bins of bw rows, each padded to its longest row (a multiple of bw slots per
   bin); returns the number of slots. The caller checks that the total fits its index type. */
template <typename I> inline long bin_starts(const I *row_ptr, I mbs, I bw, I *bin_start)
{
  const I nbins = (mbs + bw - 1) / bw;
  long    s     = 0;
  bin_start[0]  = 0;
  for (I b = 0; b < nbins; b++) {
    I len = 0;
    for (I r = b * bw; r < mbs && r < (b + 1) * bw; r++)
      len = row_ptr[r + 1] - row_ptr[r] > len ? row_ptr[r + 1] - row_ptr[r] : len;
    s += (long)len * bw;
    bin_start[b + 1] = (I)s;
  }
  return s;
}

/* col[slot] for every slot: entry k of lane l of bin b at bin_start[b] + k * bw + l; padding repeats the
   lane's last real column (0 for an empty or phantom lane) so kernels run without branches and read no x
   entry the row does not already read. diag_slot[r] (if non-null): the slot of block (r, r), or -1. */
template <typename I>
inline void bin_columns(const I *row_ptr, const I *cols, I mbs, I bw, const I *bin_start, I *col,
                        I *diag_slot)
{
  const I nbins = (mbs + bw - 1) / bw;
  for (I b = 0; b < nbins; b++) {
    const I len = (bin_start[b + 1] - bin_start[b]) / bw;
    for (I l = 0; l < bw; l++) {
      const I r    = b * bw + l;
      const I n    = r < mbs ? row_ptr[r + 1] - row_ptr[r] : 0;
      I       last = 0;
      if (r < mbs && diag_slot) diag_slot[r] = -1;
      for (I k = 0; k < n; k++) {
        const I c = cols[row_ptr[r] + k], s = bin_start[b] + k * bw + l;
        col[s] = c;
        if (c == r && diag_slot) diag_slot[r] = s;
        last = c;
      }
      for (I k = n; k < len; k++) col[bin_start[b] + k * bw + l] = last;
    }
  }
}

/* Index into the value array of entry e (row-major in the block) of slot s: the bs2 values of a group of
   bw slots are stored entry plane by entry plane, so for fixed e the bw lanes' values are contiguous. */
inline long value_index(long s, int e, int bw, int bs2)
{
  const long l = s % bw;
  return (s - l) * bs2 + (long)e * bw + l;
}

/* Slot of entry k (k-th stored block of the row, ascending column) of block row r. */
template <typename I> inline long row_slot(const I *bin_start, I bw, I r, I k)
{
  return bin_start[r / bw] + (long)k * bw + r % bw;
}

/* Whether slot group c[0 .. bw-1] of a whole-storage bin, whose lanes l with real & (1 << l) hold real
   blocks, reads x_c as bw consecutive block columns but for at most two real lanes (the test of the
   AVX-512 body's near_unit_3x8: a run anchored at the first real lane, else at the last, inside
   [0, ncols)). */
template <typename I> inline bool near_unit_group(const I *c, unsigned real, int bw, I ncols)
{
  if (!real) return false;
  int lo = 0, hi = bw - 1;
  while (!(real >> lo & 1u)) lo++;
  while (!(real >> hi & 1u)) hi--;
  for (const int anchor : {lo, hi}) {
    const long base = (long)c[anchor] - anchor;
    int        off  = 0;
    for (int l = 0; l < bw; l++) off += (real >> l & 1u) && (long)c[l] != base + l;
    if (off <= 2) return base >= 0 && base + bw <= (long)ncols;
  }
  return false;
}

/* How the AVX-512 whole-storage body reads a bin's x_c (BinMatrix::bin_xload): XC_NEAR_UNIT tests each
   slot group for consecutive columns and loads them as a block, lane by lane where the test fails;
   XC_LANES goes lane by lane without the test; XC_GATHER gathers (MAT_BINBCSR_XLOAD_GATHER, for a CPU
   whose gathers beat the lane loads). */
enum : unsigned char {
  XC_LANES     = 0,
  XC_NEAR_UNIT = 1,
  XC_GATHER    = 2
};

/* xload[b] = XC_NEAR_UNIT where at least half of bin b's slot groups pass near_unit_group, else
   XC_LANES: the hint that lets a body read x_c lane by lane in the other bins without testing each
   group (on FE matrices most groups fail the test, and its branches cost more than the loads save; a
   grid's bins pass it). Whole storage. */
template <typename I>
inline void xload_bins(const I *bin_start, const I *col, const I *row_nz, I mbs, I nbins, int bw, I ncols,
                       unsigned char *xload)
{
  for (I b = 0; b < nbins; b++) {
    const I len  = (bin_start[b + 1] - bin_start[b]) / bw;
    I       pass = 0;
    for (I k = 0; k < len; k++) {
      unsigned real = 0;
      for (int l = 0; l < bw; l++) {
        const I r = b * bw + l;
        if (r < mbs && k < row_nz[r]) real |= 1u << l;
      }
      pass += near_unit_group(col + bin_start[b] + k * bw, real, bw, ncols);
    }
    xload[b] = 2 * pass >= len ? XC_NEAR_UNIT : XC_LANES;
  }
}

} // namespace binbcsr

#endif

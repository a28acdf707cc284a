/* Bins built on the host from a block CSR matrix without PETSc (the tests, the benchmark and
   scripts/gpu_check have no PETSc): whole storage by the layout rule of binbcsr_layout.h (what
   MATSEQBINBCSR builds), symmetric storage with a greedy slot colouring (any colouring whose lanes of
   one slot group scatter to distinct columns is valid; MATSEQBINBCSR's is an edge colouring), and the
   refill map of a COO list. */
#ifndef BINBCSR_DEVICE_HOST_BINS_H
#define BINBCSR_DEVICE_HOST_BINS_H

#include "device.h"

namespace binbcsr {
namespace device {

struct HostBins {
  int                 bs = 3, bw = 8, mbs = 0;
  bool                symmetric = false;
  std::vector<int>    bin_start, col;
  std::vector<double> val; /* the bins' value array, padding zero */
  Layout              layout() const;
  /* slot of block (r, c), -1 when not stored */
  long slot(int r, int c) const;
  std::vector<std::vector<std::pair<int, int>>>
    row_slots; /* per block row: (column, slot), ascending column */
};

/* ptr[mbs + 1], cols (sorted, unique per row), vals (bs x bs row-major blocks, nullptr: zeros). With
   symmetric, blocks below the diagonal are dropped (the matrix must be symmetric for the products to be A's). */
HostBins bins_from_bcsr(int bs, int mbs, const int *ptr, const int *cols, const double *vals, int bw,
                        bool symmetric);

struct HostGather {
  long             ncoo = 0;
  std::vector<int> jmap, perm;
  GatherMap        map() const { return GatherMap{ncoo, jmap.data(), perm.data()}; }
};
/* The refill map of COO point entries (ci[p], cj[p]); entries outside the pattern, and with symmetric
   storage below the block diagonal, are ignored. */
HostGather gather_from_coo(const HostBins &B, long ncoo, const int *ci, const int *cj);

} // namespace device
} // namespace binbcsr

#endif

// What slab_gs.cpp (the layout, its refill and its passes) and slab_gs_pc.cpp (the PETSc side) share:
// the lane layout's index, the conversions into and out of it, the passes and the -log_view events.
// Internal to those two files.
#pragma once
#include "sim/slab_gs.h"

#include <vector>

namespace slab_gs_detail {

// -log_view events: the refill (blocks into the layout, diagonal blocks inverted), a smoother application
// (its sweeps), a residual
extern PetscLogEvent SLAB_Refill, SLAB_Smooth, SLAB_Residual;
PetscErrorCode       SlabGSRegisterEvents();

// Where component 0 of block row r sits in the lane layout (slab_gs.h)
inline int LaneIndex(int r, int S) { return SlabGS::lanes + (r % S) * 3 * SlabGS::lanes + r / S; }

// v (3 n values, row by row) into / out of the lane layout lv (padding lanes stay zero)
void ToLanes(const SlabGS &gs, const double *v, std::vector<double> &lv);
void FromLanes(const SlabGS &gs, const std::vector<double> &lv, double *v);

// What a pass over the layout does. The layout keeps each row's blocks toward rows of later steps (U);
// the blocks toward earlier steps (L) are their transposes, applied by pushing: once x_r is final in a
// forward pass, A_cr x_r = A_rc^T x_r goes into lower[c] for each of its later rows c, so that lower[c]
// holds (L x)_c when the pass reaches c. A backward sweep after a forward one reuses that lower sum: no
// row of L(r) changes between the two (the same bookkeeping as binbcsr's and AIJ's SOR).
enum PassMode {
  kForward,     // x_r = D^-1 (b - lower - U x), pushes
  kForwardZero, // the same from x = 0: no U products
  kBackward,    // x_r = D^-1 (b - lower - U x), backwards, lower kept from a forward pass
  kResidual,    // r = b - lower - U x - D x, pushes, x unchanged
  kLower        // lower = L x only (before a backward sweep that has no forward one before it)
};

// One pass in the lane layout: the fastest body this CPU runs (AVX-512 where it has it, else the
// lane-by-lane definition, slab_gs.cpp's PassLanes).
using PassBody = void (*)(const SlabGS &, const double *b, double *x, double *lower, double *r,
                          PassMode mode);
PassBody BestBody();

} // namespace slab_gs_detail

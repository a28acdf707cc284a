// The element loop over SIMD lanes: element_kernels.hpp's per-element functions run on batches of
// kElementLanes elements held as structure of arrays (element_batch_body.hpp). That body is compiled
// three times from the one header, in element_batch_{portable,avx2,avx512}.cpp, each with its own
// target flags (CMakeLists.txt), because the library's baseline (x86-64-v2) leaves the lane loops at
// 128-bit SSE: built that way linear_38k's element loop took 24.5 ms per step, against 14.9 ms when
// the whole build targeted the AVX-512 machine. assemble_elements_batched picks the best set this CPU
// runs at run time (binbcsr_cpu.h, the same query as the matrix product's bodies), or the one asked for.
//
// This header is what the dispatch (element_batch.cpp) and the per-set bodies share, so it holds plain
// data only: no Eigen, no STL code that a body could instantiate.
#pragma once
#include "binbcsr_cpu.h"
#include "physics/element_kernels.hpp"

#include <cstddef>
#include <vector>

namespace physics {

struct FemModel;
struct StepCoefficients;
struct BlockPattern;

// Elements per batch: 8 doubles fill an AVX-512 register, two AVX2 registers.
constexpr int kElementLanes = 8;

// Set in a BlockPattern::element_slots entry (index = entry & kSlotIndexMask) where the scalar element
// loop writes that COO block first (elements in list order; per element the pairs a <= b in order,
// (a,b) before (b,a)), and in a BlockPattern::plan write_slots entry where the batched loop does (the
// first write group touching the block): the loop stores instead of adding there, so the block values
// need no zeroing each step (the reset pass, and the loads of the first write to each block, cost ~1 ms
// per rank of linear_38k).
constexpr int kFirstContribution = 1 << 30;
constexpr int kSlotIndexMask     = kFirstContribution - 1;

// The batched loop writes its blocks out per group of kElementLanes * write_group_batches(npe) listed
// elements: it sums the contributions of the group's elements to each COO block it touches (in the
// group's stage, 45 KB for P1, 63 KB for P2) and adds each sum into the values once, the blocks in runs
// of equal term count (BlockPattern::plan). Linear_38k's 602k element blocks become 247k additions into
// its 93k COO blocks (quadratic_47k: 496k -> 344k into 202k). Groups of half or twice the size measured
// no better (twice, again with the runs: within the noise, Zen 5, 2026-12-05).
constexpr int write_group_batches(int npe) { return npe == 4 ? 8 : 2; }

// What the element loop can also measure of the state it assembles, the figures of the drivers' run
// guard: the step's own element pass has each element's positions and rotation at hand, so the health
// check need not walk the elements (and their stored K0) again. Sums over the listed elements, added to
// what the fields hold (fem_energy's terms; on several ranks each rank sums its own elements).
struct ElementEnergy {
  double elastic  = 0; // sum of u^T K0 u / 2, u = R^T x - X
  double kinetic  = 0; // sum of v^T M_e v / 2
  double inverted = 0; // elements whose corner tetrahedron's signed volume is not > 0
  // Optional: per listed element (elastic, kinetic, inverted 0 or 1), overwritten.
  double *per_element = nullptr;
};

// assemble_elements' batched body (same contract; the checks are the caller's), run by the body set
// `body` (Auto: the best this CPU runs; a set it does not run or this build lacks: the best it does).
// rotations: 9 per listed element (column-major), or null. Returns the number of elements whose
// rotation took the scalar path (inverted, flat or not converged in the fixed Newton steps).
long long assemble_elements_batched(const FemModel &model, const std::vector<int> &elements, const double *x,
                                    const double *v, const StepCoefficients &c, const BlockPattern *pattern,
                                    double *block_values, double *rhs, double *rotations,
                                    binbcsr::BodySet body   = binbcsr::BodySet::Auto,
                                    ElementEnergy   *energy = nullptr);

// The same with single-precision blocks (ElementBatchArgs::values_single).
long long assemble_elements_batched_single(const FemModel &model, const std::vector<int> &elements,
                                           const double *x, const double *v, const StepCoefficients &c,
                                           const BlockPattern *pattern, float *block_values, double *rhs,
                                           double *rotations, binbcsr::BodySet body = binbcsr::BodySet::Auto,
                                           ElementEnergy *energy = nullptr);

// The set assemble_elements_batched runs when asked for `want` (never Auto).
binbcsr::BodySet element_body_used(binbcsr::BodySet want);

// Estimated floating-point operations per element of the batched kernels (for -log_view's rates).
double element_kernel_flops(int order, bool with_blocks);

// ---- between the dispatch and the bodies ---------------------------------------------------------

// One call's inputs and outputs as plain arrays (the model's, flattened by the dispatch).
struct ElementBatchArgs {
  int  npe          = 4;
  bool corotational = true;
  // The nodes of the listed elements, npe per element in list order (BlockPattern::plan's copy: read
  // in order, not through the element numbers). Dm^-1 and the volume are not passed: the bodies
  // compute them from the rest positions (kernels::rest_shape).
  const int    *listed_nodes   = nullptr;
  std::size_t   count          = 0;       // listed elements
  std::size_t   nodes          = 0;       // the mesh's nodes (x, v, rest_positions: 3 each)
  const double *rest_positions = nullptr; // 3 per node
  const double *reference_mass = nullptr; // npe x npe (symmetric), per unit density and volume
  bool          diagonal_mass  = false;   // reference_mass is diagonal (lumped)
  // BlockPattern::plan; null: no blocks
  const int *group_offsets = nullptr, *write_slots = nullptr, *group_terms = nullptr, *run_offsets = nullptr,
            *runs                   = nullptr;
  const unsigned short *write_terms = nullptr;
  const double         *x = nullptr, *v = nullptr; // 3 per node
  double               *values        = nullptr;   // 9 per COO block, or null
  float                *values_single = nullptr;   // the same in single precision (then values is null)
  double               *rhs           = nullptr;   // 3 per node, accumulated
  double               *rotations     = nullptr;   // 9 per listed element, or null
  // The state's figures (corotational_assembly.hpp's ElementEnergy), or null: elastic and kinetic
  // energy and the inverted corner tetrahedra, summed over the listed elements and added to energy[0..2];
  // per listed element the same three into element_energy (or null).
  double                   *energy = nullptr, *element_energy = nullptr;
  kernels::ElementConstants k{};
};

// One body set's batch loop. Returns the elements that took the scalar rotation path.
using ElementBatchBody = long long (*)(const ElementBatchArgs &);

// Each set's body (its translation unit), or null where this build's compiler could not target the
// set (the file then builds as a stub). Only the dispatch calls them.
ElementBatchBody element_batch_portable();
ElementBatchBody element_batch_avx2();
ElementBatchBody element_batch_avx512();

// The scalar rotation of the elements the fixed Newton steps refuse (rotation_from_deformation: the
// sign-corrected SVD rotation). Compiled at the baseline (element_batch.cpp), since it runs Eigen.
void element_fallback_rotation(const double *F, double *R);

} // namespace physics
